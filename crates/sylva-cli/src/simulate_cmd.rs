//! `sylva simulate`: run an animation method and report how the tree moved.

use anyhow::{Context, Result, bail};
use glam::Vec3;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;
use sylva_core::methods::akagi::{Akagi, AkagiParams};
use sylva_core::methods::hsm::{Hsm, HsmParams};
use sylva_core::methods::skjermo::{Skjermo, SkjermoParams};
use sylva_core::methods::zioma::{Lod, Zioma, ZiomaParams};
use sylva_core::pose::{Pose, displacement};
use sylva_core::species::{DEFAULT_SPECIES, SpeciesSource};
use sylva_core::wind::WindScene;
use sylva_core::{Limits, Tree};

/// Animation methods available.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Zioma (GPU Gems 3 ch. 6): procedural, stateless.
    Zioma,
    /// Akagi & Kitajima §2.5: wind forces propagated to the root, damped angular springs.
    Akagi,
    /// Skjermo §4: one Bézier per stem, re-attached and bent by the wind each step.
    Skjermo,
    /// Song et al.: hierarchical shape matching, every segment and leaf a cluster of
    /// particles (CPU only so far).
    Hsm,
}

/// Where to run.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backend {
    /// CPU reference (rayon).
    Cpu,
    /// GPU (wgpu compute).
    Gpu,
}

/// The tree, method and wind a command animates (`sylva simulate`, `sylva export`).
#[derive(clap::Args, Debug)]
pub struct TreeWindArgs {
    /// A preset name, a Weber–Penn TOML file or an L-system grammar file.
    #[arg(long, short, default_value = DEFAULT_SPECIES)]
    pub species: String,
    /// Random seed of the tree (and of Zioma's branch phases).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Animation method.
    #[arg(long, value_enum, default_value = "zioma")]
    pub method: Method,
    /// A wind preset (`gusty`, `blast`) or a scene TOML file.
    #[arg(long, default_value = "gusty")]
    pub wind: String,
}

impl TreeWindArgs {
    /// Generates the tree and loads the wind.
    pub fn resolve(&self) -> Result<(Tree, WindScene)> {
        let tree = SpeciesSource::resolve(&self.species)?.generate(self.seed, &Limits::default(), None)?;
        Ok((tree, WindScene::resolve(&self.wind)?))
    }
}

/// Arguments of `sylva simulate`.
#[derive(clap::Args, Debug)]
pub struct SimulateArgs {
    /// Tree, method and wind.
    #[command(flatten)]
    pub tree: TreeWindArgs,
    /// Simulated time, s.
    #[arg(long, default_value_t = 10.0)]
    pub seconds: f32,
    /// Frames per second.
    #[arg(long, default_value_t = 60.0)]
    pub fps: f32,
    /// Backend.
    #[arg(long, value_enum, default_value = "cpu")]
    pub backend: Backend,
    /// Zioma's simulation level of detail: branches too, or the trunk only.
    #[arg(long, default_value_t = false)]
    pub trunk_only: bool,
    /// Write the trajectory of the tracked segments' end points as CSV.
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Segments to track in the CSV (default: the trunk's top and the first segment end of
    /// five branches).
    #[arg(long, value_delimiter = ',')]
    pub track: Vec<usize>,
}

const MAX_FRAMES: f32 = 10_000_000.0;

/// Removes a temporary file when dropped, unless it was renamed into place.
struct TempFile(Option<PathBuf>);

impl Drop for TempFile {
    fn drop(&mut self) {
        if let Some(p) = self.0.take() {
            let _ = std::fs::remove_file(p);
        }
    }
}

/// Runs the command.
pub fn run(a: &SimulateArgs) -> Result<()> {
    if !(a.seconds.is_finite() && a.seconds > 0.0) {
        bail!("--seconds must be a positive number, not {}", a.seconds);
    }
    if !(a.fps.is_finite() && a.fps > 0.0 && a.fps <= 10_000.0) {
        bail!("--fps must be in (0, 10000], not {}", a.fps);
    }
    let frames_f = (a.seconds * a.fps).ceil();
    if frames_f > MAX_FRAMES {
        bail!("{} frames requested; the limit is {MAX_FRAMES} (lower --seconds or --fps)", frames_f);
    }
    let frames = frames_f as usize + 1;
    let (tree, wind) = a.tree.resolve()?;
    let n = tree.segments.len();
    let track: Vec<usize> = if a.track.is_empty() { default_track(&tree) } else { a.track.clone() };
    if let Some(&bad) = track.iter().find(|&&i| i >= n) {
        bail!("--track {bad}: the tree has {n} segments (0..{})", n - 1);
    }
    if a.trunk_only && a.tree.method != Method::Zioma {
        bail!("--trunk-only is Zioma's simulation LOD; {:?} has none", a.tree.method);
    }
    let ctx = match a.backend {
        Backend::Cpu => None,
        Backend::Gpu => {
            let ctx = sylva_gpu::GpuContext::shared()?;
            println!("GPU: {}", ctx.summary);
            Some(ctx)
        }
    };
    let (fields, waves) = wind.pack();
    let (tree_ref, wind_ref) = (&tree, &wind);
    // One closure per method and backend: (time, step since the last frame) → pose.
    type Runner<'a> = Box<dyn FnMut(f32, f32) -> Result<Pose> + 'a>;
    let mut runner: Runner<'_> = match (a.tree.method, ctx) {
        (Method::Zioma, ctx) => {
            let params = ZiomaParams {
                lod: if a.trunk_only { Lod::TrunkOnly } else { Lod::Full },
                seed: a.tree.seed,
                ..Default::default()
            };
            let method = Zioma::new(tree_ref, params);
            match ctx {
                None => Box::new(move |t, _| Ok(method.pose_packed(tree_ref, &fields, &waves, t))),
                Some(ctx) => {
                    let g = sylva_gpu::pose::GpuZioma::new(ctx, tree_ref, &method, wind_ref)?;
                    Box::new(move |t, _| Ok(g.pose(ctx, tree_ref, &method, t)?))
                }
            }
        }
        (Method::Akagi, None) => {
            let method = Akagi::new(tree_ref, AkagiParams::default());
            let mut state = method.rest_state(tree_ref);
            Box::new(move |_, dt| {
                if dt > 0.0 {
                    method.step(tree_ref, &fields, &waves, &mut state, dt);
                }
                Ok(state.pose.clone())
            })
        }
        (Method::Skjermo, None) => {
            let method = Skjermo::new(tree_ref, SkjermoParams::default());
            let mut state = method.rest_state(tree_ref);
            Box::new(move |_, dt| {
                if dt > 0.0 {
                    method.step(tree_ref, &fields, &waves, &mut state, dt);
                }
                Ok(state.pose.clone())
            })
        }
        (Method::Skjermo, Some(ctx)) => {
            let method = Skjermo::new(tree_ref, SkjermoParams::default());
            let mut g = sylva_gpu::pose::GpuSkjermo::new(ctx, tree_ref, &method, wind_ref)?;
            Box::new(move |_, dt| {
                if dt > 0.0 {
                    g.step(ctx, dt);
                }
                Ok(g.read(ctx, &method)?)
            })
        }
        (Method::Hsm, None) => {
            let method = Hsm::new(tree_ref, HsmParams::default())?;
            println!("hsm: {} clusters, {} particles", method.layout.cluster_count(), method.layout.particle_count());
            let mut state = method.rest_state();
            Box::new(move |_, dt| {
                if dt > 0.0 {
                    method.step(&fields, &waves, &mut state, dt);
                }
                Ok(method.pose(tree_ref, &state))
            })
        }
        (Method::Hsm, Some(ctx)) => {
            let method = Hsm::new(tree_ref, HsmParams::default())?;
            println!("hsm: {} clusters, {} particles", method.layout.cluster_count(), method.layout.particle_count());
            let mut g = sylva_gpu::hsm::GpuHsm::new(ctx, Some(tree_ref), &method, wind_ref)?;
            Box::new(move |_, dt| {
                if dt > 0.0 {
                    g.step(ctx, &method, dt);
                }
                Ok(g.read_pose(ctx)?.expect("built with the tree"))
            })
        }
        (Method::Akagi, Some(ctx)) => {
            let method = Akagi::new(tree_ref, AkagiParams::default());
            let mut g = sylva_gpu::pose::GpuAkagi::new(ctx, tree_ref, &method, wind_ref)?;
            Box::new(move |_, dt| {
                if dt > 0.0 {
                    g.step(ctx, dt);
                }
                Ok(g.read(ctx)?)
            })
        }
    };

    let mut guard = TempFile(None);
    let mut csv = match &a.csv {
        Some(p) => {
            let tmp = p.with_extension("csv.tmp");
            guard.0 = Some(tmp.clone());
            let mut f = std::io::BufWriter::new(
                std::fs::File::create(&tmp).with_context(|| format!("creating {}", tmp.display()))?,
            );
            writeln!(f, "time_s,segment,level,x,y,z,dx,dy,dz")?;
            Some((p.clone(), tmp, f))
        }
        None => None,
    };
    let levels = tree.levels as usize;
    let (mut sum_mean, mut max_disp) = (vec![0.0f64; levels], vec![0.0f32; levels]);
    let mut max_speed = 0.0f32;
    let mut prev: Option<Vec<Vec3>> = None;
    let bar = ProgressBar::new(frames as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} frames {elapsed} (eta {eta})").expect("valid template"),
    );
    let start = Instant::now();
    let dt = 1.0 / a.fps;
    for f in 0..frames {
        let t = f as f32 * dt;
        let pose = runner(t, if f == 0 { 0.0 } else { dt })?;
        let d = displacement(&tree, &pose);
        for l in 0..levels {
            sum_mean[l] += d.mean[l] as f64;
            max_disp[l] = max_disp[l].max(d.max[l]);
        }
        let ends: Vec<Vec3> = (0..n).map(|i| pose.end(&tree, i)).collect();
        if let Some(p) = &prev {
            for i in 0..n {
                max_speed = max_speed.max((ends[i] - p[i]).length() / dt);
            }
        }
        if let Some((_, _, w)) = &mut csv {
            for &i in &track {
                let r = tree.segments.end(i);
                let e = ends[i];
                writeln!(
                    w,
                    "{t},{i},{},{},{},{},{},{},{}",
                    tree.segments.level[i],
                    e.x,
                    e.y,
                    e.z,
                    e.x - r.x,
                    e.y - r.y,
                    e.z - r.z
                )?;
            }
        }
        prev = Some(ends);
        bar.inc(1);
    }
    bar.finish_and_clear();
    let elapsed = start.elapsed().as_secs_f64();
    if let Some((path, tmp, w)) = csv {
        w.into_inner().map_err(|e| e.into_error())?.sync_all()?;
        std::fs::rename(&tmp, &path).with_context(|| format!("writing {}", path.display()))?;
        guard.0 = None;
        println!("wrote {} ({} tracked segments × {frames} frames)", path.display(), track.len());
    }
    println!(
        "{} (seed {}), {:?} on {:?}, wind `{}`: {} frames over {} s in {:.2} s ({:.2} ms per frame)",
        tree.name,
        tree.seed,
        a.tree.method,
        a.backend,
        a.tree.wind,
        frames,
        a.seconds,
        elapsed,
        1e3 * elapsed / frames as f64
    );
    println!("  {:>5} {:>16} {:>14}", "level", "mean tip disp m", "max tip disp m");
    for l in 0..levels {
        println!("  {:>5} {:>16.4} {:>14.4}", l, sum_mean[l] / frames as f64, max_disp[l]);
    }
    println!("  largest segment-end speed {max_speed:.3} m/s");
    Ok(())
}

fn default_track(t: &Tree) -> Vec<usize> {
    let st = &t.stems;
    let mut out = vec![(st.first_segment[0] + st.segment_count[0] - 1) as usize];
    let branches: Vec<usize> = (0..st.len()).filter(|&k| st.level[k] == 1).collect();
    for k in branches.iter().step_by((branches.len() / 5).max(1)).take(5) {
        out.push((st.first_segment[*k] + st.segment_count[*k] - 1) as usize);
    }
    out
}

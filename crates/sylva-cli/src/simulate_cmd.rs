//! `sylva simulate`: run an animation method and report how the tree moved.

use anyhow::{Context, Result, bail};
use clap::ValueEnum;
use glam::Vec3;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::Write;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;
use sylva_core::Tree;
use sylva_core::io::PendingFile;
use sylva_core::methods::{Animator, MethodOptions};
use sylva_core::pose::{Pose, displacement};
use sylva_core::species::{DEFAULT_SPECIES, SpeciesSource};
use sylva_core::wind::WindScene;
use sylva_gpu::methods::GpuAnimator;
use sylva_runtime::{BUILTIN, MethodRegistry};

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
    #[arg(long, default_value = "zioma", value_parser = clap::builder::PossibleValuesParser::new(BUILTIN.map(|e| e.name)))]
    pub method: String,
    /// A wind preset (`gusty`, `blast`, `eddies`) or a scene TOML file.
    #[arg(long, default_value = "gusty")]
    pub wind: String,
    /// A method parameter as `name=value` (TOML value: `damping_ratio=0.1`, `lod="trunk_only"`);
    /// repeat for several. The names are the method's `Params` fields.
    #[arg(long = "param", value_parser = parse_param)]
    pub params: Vec<(String, toml::Value)>,
    #[command(flatten)]
    pub limits: crate::limit_args::LimitArgs,
}

/// `name=value` with a TOML value (a bare word is a string).
fn parse_param(s: &str) -> Result<(String, toml::Value), String> {
    let (k, v) = s.split_once('=').ok_or_else(|| format!("`{s}`: expected name=value, e.g. damping_ratio=0.1"))?;
    let v = v.trim();
    let value = toml::from_str::<toml::Table>(&format!("v = {v}"))
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(v.to_string()));
    Ok((k.trim().to_string(), value))
}

impl TreeWindArgs {
    /// Generates the tree and loads the wind.
    pub fn resolve(&self) -> Result<(Tree, WindScene)> {
        let limits = self.limits.limits();
        let tree = SpeciesSource::resolve_with(&self.species, &limits)?.generate(self.seed, &limits, None)?;
        Ok((tree, WindScene::resolve(&self.wind)?))
    }

    /// The method's options: the seed and the `--param`s.
    pub fn options(&self) -> MethodOptions {
        MethodOptions { seed: self.seed, params: self.params.iter().cloned().collect() }
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
    let mut options = a.tree.options();
    if a.trunk_only {
        options.params.insert("lod".into(), toml::Value::String("trunk_only".into()));
    }
    let built = |e: sylva_core::methods::MethodError| {
        let e = anyhow::Error::from(e);
        if a.trunk_only { e.context("--trunk-only sets Zioma's simulation LOD (`lod = \"trunk_only\"`)") } else { e }
    };
    let registry = MethodRegistry::builtin();
    let entry = *registry.entry(&a.tree.method)?;
    let tree = Arc::new(tree);
    enum Sim {
        Cpu(Box<dyn Animator>),
        Gpu(&'static sylva_gpu::GpuContext, Box<dyn GpuAnimator>),
    }
    // Building can take a while (HSM measures its own stems, `methods/hsm/calibrate.rs`: about
    // a minute on the black oak): a spinner on the terminal says so.
    let building = ProgressBar::new_spinner()
        .with_message(format!("building {} on the tree", entry.name))
        .with_finish(indicatif::ProgressFinish::AndClear);
    building.set_style(ProgressStyle::with_template("{spinner} {msg} {elapsed}").expect("valid template"));
    building.enable_steady_tick(std::time::Duration::from_millis(200));
    let mut sim = match a.backend {
        Backend::Cpu => {
            let mut m = (entry.cpu)(tree.clone(), &options).map_err(built)?;
            m.set_wind(Arc::new(wind.packed()));
            Sim::Cpu(m)
        }
        Backend::Gpu => {
            let ctx = sylva_gpu::GpuContext::shared()?;
            building.suspend(|| println!("GPU: {}", ctx.summary));
            let build = entry.gpu.with_context(|| format!("method `{}` has no GPU twin", entry.name))?;
            let gpu_wind = sylva_gpu::wind::GpuWind::from_scene(ctx, &wind)?;
            let m = build(ctx, tree.clone(), &options, &gpu_wind, &[]).map_err(|e| match e {
                sylva_gpu::methods::BuildError::Method(m) => built(m),
                sylva_gpu::methods::BuildError::Gpu(g) => g.into(),
            })?;
            Sim::Gpu(ctx, m)
        }
    };
    building.finish_and_clear();
    let (particles, clusters) = match &sim {
        Sim::Cpu(m) => (m.particles(), m.cluster_centres().map(|c| c.len())),
        Sim::Gpu(ctx, m) => (m.particles(), m.cluster_centres(ctx)?.map(|c| c.len())),
    };
    if let (Some(p), Some(c)) = (particles, clusters) {
        println!("{}: {c} clusters, {p} particles", entry.name);
    }
    let mut csv = match &a.csv {
        Some(p) => {
            let pending = PendingFile::new(p).with_context(|| format!("writing {}", p.display()))?;
            let mut f = std::io::BufWriter::new(
                pending.create().with_context(|| format!("creating {}", pending.tmp().display()))?,
            );
            writeln!(f, "time_s,segment,level,x,y,z,dx,dy,dz").with_context(|| format!("writing {}", p.display()))?;
            Some((pending, f))
        }
        None => None,
    };
    let levels = tree.levels as usize;
    let (mut sum_mean, mut max_disp) = (vec![0.0f64; levels], vec![0.0f32; levels]);
    let mut max_speed = 0.0f32;
    let (mut leaf_sum2, mut leaf_count, mut leaf_max) = (0.0f64, 0u64, 0.0f32);
    let mut seam = sylva_core::pose::SeamPose::default();
    let mut prev: Option<Vec<Vec3>> = None;
    let bar = ProgressBar::new(frames as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} frames {elapsed} (eta {eta})").expect("valid template"),
    );
    let start = Instant::now();
    let dt = 1.0 / a.fps;
    for f in 0..frames {
        let t = f as f32 * dt;
        let steps = if f == 0 { 0 } else { 1 };
        let pose: Pose = match &mut sim {
            Sim::Cpu(m) => {
                m.advance(dt, steps);
                m.seam(&mut seam);
                seam.pose(&tree, 0)
            }
            Sim::Gpu(ctx, m) => {
                m.advance(ctx, dt, steps);
                seam.leaf = m.pose_buffers().read_leaves(ctx)?;
                m.read_pose(ctx)?
            }
        };
        // Each leaf's turn relative to its segment: the angle of its rotation λ.
        for q in &seam.leaf {
            let a = 2.0 * q[3].abs().min(1.0).acos();
            leaf_sum2 += (a as f64).powi(2);
            leaf_max = leaf_max.max(a);
        }
        leaf_count += seam.leaf.len() as u64;
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
        if let Some((pending, w)) = &mut csv {
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
                )
                .with_context(|| format!("writing {}", pending.path().display()))?;
            }
        }
        prev = Some(ends);
        bar.inc(1);
    }
    bar.finish_and_clear();
    let elapsed = start.elapsed().as_secs_f64();
    if let Some((pending, w)) = csv {
        let path = pending.path().to_path_buf();
        w.into_inner().map_err(|e| e.into_error()).with_context(|| format!("writing {}", path.display()))?;
        pending.commit().with_context(|| format!("writing {}", path.display()))?;
        println!("wrote {} ({} tracked segments × {frames} frames)", path.display(), track.len());
    }
    println!(
        "{} (seed {}), {} on the {}, wind `{}`: {} frames over {} s in {:.2} s ({:.2} ms per frame)",
        tree.name,
        tree.seed,
        a.tree.method,
        a.backend.to_possible_value().map_or_else(String::new, |v| v.get_name().to_uppercase()),
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
    if leaf_count > 0 {
        println!(
            "  leaves turn relative to their segments by {:.2}° RMS, {:.2}° at most",
            (leaf_sum2 / leaf_count as f64).sqrt().to_degrees(),
            leaf_max.to_degrees()
        );
    }
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

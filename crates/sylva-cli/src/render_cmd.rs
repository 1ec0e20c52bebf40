//! `sylva render`: the main job. The runtime's world grows every tree of a scene, animates
//! each with its method (CPU or GPU) and meshes every frame on the GPU; this renders it
//! (sun, shadows, sky, ground, instancing) and writes a GIF, PNG frames and, when `ffmpeg` is
//! installed, an MP4 — each file complete or not at all, whatever signal arrives.

use anyhow::{Context, Result, bail};
use glam::Vec3;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::Write;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;
use sylva_core::io::{PendingDir, PendingFile};
use sylva_core::scene::{BackendChoice, Scene};
use sylva_gpu::GpuContext;
use sylva_gpu::render::{Camera, Lighting, RenderSettings, Renderer};
use sylva_runtime::{MethodRegistry, World, WorldTree};

/// Arguments of `sylva render`.
#[derive(clap::Args, Debug, Default)]
pub struct RenderArgs {
    /// Scene file (TOML); the built-in default scene when absent.
    pub scene: Option<PathBuf>,
    /// Output directory (overrides the scene's).
    #[arg(long)]
    pub out_dir: Option<PathBuf>,
    /// Image width (overrides the scene's).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height (overrides the scene's).
    #[arg(long)]
    pub height: Option<u32>,
    /// Duration, s (overrides the scene's).
    #[arg(long)]
    pub seconds: Option<f32>,
    /// Frames per second (overrides the scene's).
    #[arg(long)]
    pub fps: Option<f32>,
    /// Where every tree's simulation runs (overrides each tree's `backend`).
    #[arg(long, value_enum)]
    pub backend: Option<BackendArg>,
    /// Write no MP4 even when ffmpeg is installed.
    #[arg(long)]
    pub no_mp4: bool,
    /// Write no PNG frames.
    #[arg(long)]
    pub no_png: bool,
    #[command(flatten)]
    pub limits: crate::limit_args::LimitArgs,
}

/// Backend override.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum BackendArg {
    /// GPU on hardware adapters, CPU on software rasterisers.
    Auto,
    /// CPU reference.
    Cpu,
    /// GPU kernels.
    Gpu,
}

fn ffmpeg_available() -> bool {
    std::process::Command::new("ffmpeg")
        .arg("-version")
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// Draws labels (white on a dark shadow) onto an RGBA image.
fn draw_labels(rgba: &mut [u8], w: u32, h: u32, labels: &[(String, f32, f32)]) -> Result<()> {
    use plotters::prelude::*;
    use plotters::style::text_anchor::{HPos, Pos, VPos};
    let mut rgb: Vec<u8> = rgba.chunks(4).flat_map(|p| [p[0], p[1], p[2]]).collect();
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
        let size = (h as f64 / 30.0).clamp(10.0, 40.0);
        for (text, x, y) in labels {
            let (x, y) = (*x as i32, *y as i32);
            let pos = Pos::new(HPos::Center, VPos::Top);
            for (dx, c) in [(1, RGBColor(20, 20, 20)), (0, RGBColor(250, 250, 245))] {
                let style = TextStyle::from(("sans-serif", size).into_font()).color(&c).pos(pos);
                root.draw(&Text::new(text.as_str(), (x + dx, y + dx), style))
                    .map_err(|e| anyhow::anyhow!("drawing a label: {e}"))?;
            }
        }
        root.present().map_err(|e| anyhow::anyhow!("drawing labels: {e}"))?;
    }
    for (d, s) in rgba.chunks_mut(4).zip(rgb.chunks(3)) {
        d[..3].copy_from_slice(s);
    }
    Ok(())
}

/// Runs the command.
pub fn run(a: &RenderArgs) -> Result<()> {
    let mut scene = match &a.scene {
        Some(p) => Scene::load(p)?,
        None => Scene::default_scene(),
    };
    if let Some(d) = &a.out_dir {
        scene.output.dir = d.clone();
    }
    if let Some(v) = a.width {
        scene.output.width = v;
    }
    if let Some(v) = a.height {
        scene.output.height = v;
    }
    if let Some(v) = a.seconds {
        scene.output.seconds = v;
    }
    if let Some(v) = a.fps {
        scene.output.fps = v;
    }
    if a.no_mp4 {
        scene.output.mp4 = false;
    }
    if a.no_png {
        scene.output.png = false;
    }
    scene.limits = a.limits.limits();
    if let Some(b) = a.backend {
        for t in &mut scene.trees {
            t.backend = match b {
                BackendArg::Auto => BackendChoice::Auto,
                BackendArg::Cpu => BackendChoice::Cpu,
                BackendArg::Gpu => BackendChoice::Gpu,
            };
        }
    }
    scene.check().map_err(|(field, value, expected)| {
        // A value from a flag is the flag's fault, not the scene file's.
        let flag = match field.as_str() {
            "output.width" if a.width.is_some() => Some("--width"),
            "output.height" if a.height.is_some() => Some("--height"),
            "output.seconds" if a.seconds.is_some() => Some("--seconds"),
            "output.fps" if a.fps.is_some() => Some("--fps"),
            _ => None,
        };
        match flag {
            Some(flag) => anyhow::anyhow!("{flag} {value}: expected {expected}"),
            None => anyhow::anyhow!("{}: field `{field}` = {value}: expected {expected}", scene.file),
        }
    })?;
    // Stop between frames on a signal, so that ffmpeg is stopped before its file is removed.
    crate::signals::graceful();
    render(&scene)
}

fn render(scene: &Scene) -> Result<()> {
    let o = &scene.output;
    let ctx = GpuContext::shared_arc()?;
    println!("GPU: {}", ctx.summary);
    let steps = (o.sim_rate / o.fps).round().max(1.0) as usize;
    let dt = 1.0 / (o.fps * steps as f32);
    let setup = Instant::now();
    let mut world = World::with(ctx.clone(), scene.clone(), Arc::new(MethodRegistry::builtin()), dt)?;
    for t in world.trees() {
        println!("{}", t.summary());
    }
    let ctx = &*ctx;
    let renderer =
        Renderer::new(ctx, RenderSettings { width: o.width, height: o.height, msaa: o.msaa, ..Default::default() })?;
    let camera = Camera {
        eye: Vec3::from_array(scene.camera.eye),
        target: Vec3::from_array(scene.camera.target),
        fov_y_deg: scene.camera.fov_deg,
    };
    let light = Lighting {
        sun_direction: Vec3::from_array(scene.sun.direction).normalize(),
        sun_intensity: scene.sun.intensity,
        ..Default::default()
    };
    let globals = renderer.globals(&camera, &light, world.bounds());
    let view_proj = camera.view_proj(o.width as f32 / o.height as f32);
    let labels: Vec<(String, f32, f32)> = if o.labels {
        world
            .trees()
            .iter()
            .enumerate()
            .filter_map(|(k, e)| {
                let c = view_proj * e.base.extend(1.0);
                // Alternate rows so neighbours' labels do not overlap.
                let row = (k % 2) as f32 * (o.height as f32 / 26.0).clamp(12.0, 44.0);
                (c.w > 0.0).then(|| {
                    let n = c.truncate() / c.w;
                    let (x, y) = ((n.x * 0.5 + 0.5) * o.width as f32, (0.5 - n.y * 0.5) * o.height as f32);
                    (e.label.clone(), x, y + 6.0 + row)
                })
            })
            .collect()
    } else {
        Vec::new()
    };
    if o.labels {
        sylva_bench::plot::register_font();
    }

    std::fs::create_dir_all(&o.dir).with_context(|| format!("creating {}", o.dir.display()))?;
    // Frames go to a temporary directory and replace the earlier run's only when all are
    // written: an interrupted or failed render leaves `frames/` as it was.
    let frames_dir = o.dir.join("frames");
    let frames_pending = o
        .png
        .then(|| PendingDir::new(&o.dir, "frames"))
        .transpose()
        .with_context(|| format!("creating a temporary directory in {}", o.dir.display()))?;
    let frames = scene.frames();
    let gif_path = o.dir.join(format!("{}.gif", o.name));
    let gif_pending = o.gif.then(|| PendingFile::new(&gif_path)).transpose()?;
    // The encoder borrows the writer, so that the writer's flush reports a full disk (the
    // encoder's drop, which writes the trailer, would swallow it).
    let mut gif_writer = match &gif_pending {
        Some(p) => {
            Some(std::io::BufWriter::new(p.create().with_context(|| format!("creating {}", p.tmp().display()))?))
        }
        None => None,
    };
    let mut gif = match &mut gif_writer {
        Some(w) => {
            let mut enc = image::codecs::gif::GifEncoder::new_with_speed(w, 10);
            enc.set_repeat(image::codecs::gif::Repeat::Infinite)
                .with_context(|| format!("writing {}", gif_path.display()))?;
            Some(enc)
        }
        None => None,
    };
    let mp4_path = o.dir.join(format!("{}.mp4", o.name));
    let mp4_pending = (o.mp4 && ffmpeg_available()).then(|| PendingFile::new(&mp4_path)).transpose()?;
    let mut ffmpeg = match &mp4_pending {
        Some(p) => Some(
            std::process::Command::new("ffmpeg")
                .args(["-loglevel", "error", "-y", "-f", "rawvideo", "-pix_fmt", "rgba", "-s"])
                .arg(format!("{}x{}", o.width, o.height))
                .args(["-r", &o.fps.to_string(), "-i", "-", "-c:v", "libx264", "-pix_fmt", "yuv420p"])
                .args(["-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-movflags", "+faststart", "-f", "mp4"])
                .arg(p.tmp())
                .stdin(std::process::Stdio::piped())
                .spawn()
                .context("starting ffmpeg")?,
        ),
        None => None,
    };

    // Pre-roll: stateful methods start at rest; let the wind move them first.
    // Phase groups pre-roll further, each by its own lead.
    let preroll_steps = (o.preroll * o.fps * steps as f32).round() as usize;
    let prerolled = preroll_steps > 0 || world.trees().iter().any(WorldTree::has_leads);
    if prerolled {
        world.preroll(preroll_steps);
    }
    let triangles = world.triangles();
    println!("set up in {:.2} s; {} triangles per frame", setup.elapsed().as_secs_f64(), triangles);

    let bar = ProgressBar::new(frames as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} frames {elapsed} (eta {eta})").expect("valid template"),
    );
    let start = Instant::now();
    let (mut sim_s, mut draw_s, mut encode_s) = (0.0f64, 0.0f64, 0.0f64);
    // The GPU's own time for the simulation and meshing (the leaf kernels included), where
    // the adapter has timestamp queries: that work is submitted apart from the drawing.
    let timer = sylva_gpu::timer::GpuTimer::new(ctx);
    let mut gpu_sim_s: Option<f64> = timer.as_ref().map(|_| 0.0);
    for f in 0..frames {
        if crate::signals::interrupted() {
            bar.abandon();
            if let Some(mut child) = ffmpeg.take() {
                let _ = child.kill();
                let _ = child.wait();
            }
            bail!(
                "{} after {f} of {frames} frames: stopped; no partial output was written",
                crate::signals::received().unwrap_or("interrupted")
            );
        }
        let t0 = Instant::now();
        if let Some(t) = &timer {
            t.start(ctx);
        }
        world.step(if f == 0 && prerolled { 0 } else { steps })?;
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        world.record(&mut encoder);
        if let Some(t) = &timer {
            ctx.submit([encoder.finish()]);
            t.stop(ctx);
            encoder = ctx.device.create_command_encoder(&Default::default());
        }
        let t1 = Instant::now();
        renderer.record(ctx, &mut encoder, &globals, &world.draw_items());
        let mut rgba = renderer.read_image(ctx, encoder)?;
        let t2 = Instant::now();
        if let (Some(t), Some(total)) = (&timer, &mut gpu_sim_s) {
            *total += t.read(ctx)?.map_or(0.0, |d| d.as_secs_f64());
        }
        draw_labels(&mut rgba, o.width, o.height, &labels)?;
        let img = image::RgbaImage::from_raw(o.width, o.height, rgba).context("image size")?;
        if let Some(dir) = &frames_pending {
            let path = dir.tmp().join(format!("{}_{f:04}.png", o.name));
            let mut png = Vec::new();
            img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
                .context("encoding a PNG frame")?;
            std::fs::write(&path, &png).with_context(|| format!("writing {}", path.display()))?;
        }
        if let Some(enc) = &mut gif {
            let delay = image::Delay::from_numer_denom_ms(1000, o.fps.round().max(1.0) as u32);
            enc.encode_frame(image::Frame::from_parts(img.clone(), 0, 0, delay))
                .with_context(|| format!("writing {}", gif_path.display()))?;
        }
        if let Some(child) = &mut ffmpeg {
            child.stdin.as_mut().context("ffmpeg stdin")?.write_all(img.as_raw()).context("feeding ffmpeg")?;
        }
        sim_s += (t1 - t0).as_secs_f64();
        draw_s += (t2 - t1).as_secs_f64();
        encode_s += t2.elapsed().as_secs_f64();
        bar.inc(1);
    }
    bar.finish_and_clear();
    drop(gif);
    if let (Some(w), Some(p)) = (gif_writer, gif_pending) {
        w.into_inner().map_err(|e| e.into_error()).with_context(|| format!("writing {}", gif_path.display()))?;
        p.commit().with_context(|| format!("writing {}", gif_path.display()))?;
        println!("wrote {}", gif_path.display());
    }
    if let (Some(mut child), Some(p)) = (ffmpeg, mp4_pending) {
        drop(child.stdin.take());
        let status = child.wait().context("waiting for ffmpeg")?;
        if !status.success() {
            bail!("ffmpeg failed ({status}); no MP4 written");
        }
        p.commit().with_context(|| format!("writing {}", mp4_path.display()))?;
        println!("wrote {}", mp4_path.display());
    }
    if let Some(dir) = frames_pending {
        let prefix = format!("{}_", o.name);
        let stale = |name: &str| {
            name.strip_prefix(&prefix)
                .and_then(|r| r.strip_suffix(".png"))
                .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
        };
        dir.commit(&frames_dir, stale).with_context(|| format!("moving the frames into {}", frames_dir.display()))?;
        println!("wrote {} frames to {}", frames, frames_dir.display());
    }
    let n = frames as f64;
    println!(
        "{frames} frames of {}×{} in {:.2} s: {:.1} ms per frame (simulate + mesh recording {:.1}, GPU mesh + draw + readback {:.1}, labels + encoding {:.1})",
        o.width,
        o.height,
        start.elapsed().as_secs_f64(),
        1e3 * start.elapsed().as_secs_f64() / n,
        1e3 * sim_s / n,
        1e3 * draw_s / n,
        1e3 * encode_s / n
    );
    if let Some(g) = gpu_sim_s {
        println!("GPU time of simulation + meshing (timestamp queries): {:.3} ms per frame", 1e3 * g / n);
    }
    Ok(())
}

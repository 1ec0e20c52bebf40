//! `sylva wind`: plots of a wind scene, so a user can see the wind they authored.
//!
//! * `wind_speed.png`: speed and components at one point over a time range;
//! * `wind_field.png`: a top-down map (colour = speed, arrows = horizontal direction) of a
//!   horizontal slice at one time.

use anyhow::{Context, Result, bail};
use glam::Vec3;
use plotters::prelude::*;
use std::path::{Path, PathBuf};
use sylva_bench::plot::pending_png;
use sylva_core::io::PendingFile;
use sylva_core::wind::WindScene;
use sylva_core::wind::sample::wind_sample;

/// Picks one curve's value from (velocity, speed).
type Component = Box<dyn Fn(&[f32; 4], f32) -> f32>;

/// Arguments of `sylva wind`.
#[derive(clap::Args, Debug)]
pub struct WindArgs {
    /// A wind preset (`gusty`, `blast`, `eddies`) or a scene TOML file.
    #[arg(long, default_value = "gusty")]
    pub scene: String,
    /// Point for the speed plot, `x,y,z` in metres.
    #[arg(long, default_value = "0,5,0", value_parser = parse_vec3)]
    pub point: Vec3,
    /// Start of the time range, s.
    #[arg(long, default_value_t = 0.0)]
    pub from: f32,
    /// End of the time range, s.
    #[arg(long, default_value_t = 60.0)]
    pub to: f32,
    /// Time of the top-down map, s.
    #[arg(long, default_value_t = 10.0)]
    pub time: f32,
    /// Half-size of the top-down map, m.
    #[arg(long, default_value_t = 100.0)]
    pub extent: f32,
    /// Height of the map's horizontal slice, m.
    #[arg(long, default_value_t = 5.0)]
    pub height: f32,
    /// Evaluate on `cpu` (the reference) or `gpu`.
    #[arg(long, default_value = "cpu")]
    pub backend: String,
    /// Output folder.
    #[arg(long, default_value = "out/wind")]
    pub out_dir: PathBuf,
}

fn parse_vec3(s: &str) -> Result<Vec3, String> {
    let v: Vec<f32> =
        s.split(',').map(|p| p.trim().parse::<f32>()).collect::<Result<_, _>>().map_err(|e| format!("`{s}`: {e}"))?;
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(Vec3::new(x, y, z)),
        _ => Err(format!("`{s}`: expected three finite numbers x,y,z")),
    }
}

fn sample(scene: &WindScene, backend: &str, samples: &[[f32; 4]]) -> Result<Vec<[f32; 4]>> {
    match backend {
        "cpu" => {
            let (f, w) = scene.pack();
            let mut out = vec![[0.0; 4]; samples.len()];
            wind_sample(&f, &w, samples, &mut out);
            Ok(out)
        }
        "gpu" => {
            let ctx = sylva_gpu::GpuContext::shared()?;
            Ok(sylva_gpu::wind::WindSampler::new(ctx, scene)?.sample(ctx, samples)?)
        }
        other => bail!("--backend must be `cpu` or `gpu`, not `{other}`"),
    }
}

/// Runs the command; returns the two files written.
pub fn run(args: &WindArgs) -> Result<[PathBuf; 2]> {
    if args.to <= args.from || !args.from.is_finite() || !args.to.is_finite() {
        bail!("--to ({}) must be after --from ({})", args.to, args.from);
    }
    if args.extent <= 0.0 || !args.extent.is_finite() {
        bail!("--extent must be a positive number of metres, not {}", args.extent);
    }
    let scene = WindScene::resolve(&args.scene)?;
    if args.backend == "gpu" {
        // No adapter: say so before anything is created.
        sylva_gpu::GpuContext::shared()?;
    }
    std::fs::create_dir_all(&args.out_dir).with_context(|| format!("creating {}", args.out_dir.display()))?;
    sylva_bench::plot::register_font();
    let speed = args.out_dir.join("wind_speed.png");
    let field = args.out_dir.join("wind_field.png");
    // Both plots are drawn before either takes its name: the pair appears together.
    let plots = [speed_plot(&scene, args, &speed)?, field_map(&scene, args, &field)?];
    for (plot, path) in plots.into_iter().zip([&speed, &field]) {
        plot.commit().with_context(|| format!("writing {}", path.display()))?;
    }
    Ok([speed, field])
}

fn speed_plot(scene: &WindScene, a: &WindArgs, path: &Path) -> Result<PendingFile> {
    let n = 2000usize;
    let ts: Vec<f32> = (0..n).map(|i| a.from + (a.to - a.from) * i as f32 / (n - 1) as f32).collect();
    let samples: Vec<[f32; 4]> = ts.iter().map(|&t| [a.point.x, a.point.y, a.point.z, t]).collect();
    let v = sample(scene, &a.backend, &samples)?;
    let speed: Vec<f32> = v.iter().map(|v| Vec3::new(v[0], v[1], v[2]).length()).collect();
    let lo = v.iter().flat_map(|v| v[..3].iter().cloned()).fold(0.0f32, f32::min);
    let hi = speed.iter().cloned().fold(0.0f32, f32::max).max(0.1);
    pending_png(path, (1200, 600), |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(
                format!("Wind at ({}, {}, {}) m — {}", a.point.x, a.point.y, a.point.z, a.scene),
                ("sans-serif", 24),
            )
            .margin(15)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(a.from..a.to, (lo * 1.1).min(0.0)..hi * 1.1)?;
        chart.configure_mesh().x_desc("time (s)").y_desc("m/s").label_style(("sans-serif", 14)).draw()?;
        let series: [(&str, RGBColor, Component); 4] = [
            ("speed", BLACK, Box::new(|_, s| s)),
            ("x", RED, Box::new(|v, _| v[0])),
            ("y (up)", GREEN, Box::new(|v, _| v[1])),
            ("z", BLUE, Box::new(|v, _| v[2])),
        ];
        for (name, colour, f) in series {
            chart
                .draw_series(LineSeries::new(
                    ts.iter().zip(&v).zip(&speed).map(|((t, v), s)| (*t, f(v, *s))),
                    colour.stroke_width(if name == "speed" { 2 } else { 1 }),
                ))?
                .label(name)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .draw()?;
        Ok(())
    })
}

fn field_map(scene: &WindScene, a: &WindArgs, path: &Path) -> Result<PendingFile> {
    let cells = 200usize;
    let e = a.extent;
    let at = |i: usize| -e + 2.0 * e * (i as f32 + 0.5) / cells as f32;
    let samples: Vec<[f32; 4]> = (0..cells * cells).map(|k| [at(k % cells), a.height, at(k / cells), a.time]).collect();
    let v = sample(scene, &a.backend, &samples)?;
    let speed: Vec<f32> = v.iter().map(|v| Vec3::new(v[0], v[1], v[2]).length()).collect();
    let vmax = speed.iter().cloned().fold(0.0f32, f32::max).max(0.1);
    let arrows = 20usize;
    let arrow_samples: Vec<[f32; 4]> = (0..arrows * arrows)
        .map(|k| {
            let g = |i: usize| -e + 2.0 * e * (i as f32 + 0.5) / arrows as f32;
            [g(k % arrows), a.height, g(k / arrows), a.time]
        })
        .collect();
    let av = sample(scene, &a.backend, &arrow_samples)?;
    pending_png(path, (900, 900), |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(
                format!("Wind at t = {} s, height {} m (max {:.1} m/s) — {}", a.time, a.height, vmax, a.scene),
                ("sans-serif", 22),
            )
            .margin(15)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(-e..e, -e..e)?;
        chart.configure_mesh().x_desc("x (m)").y_desc("z (m)").label_style(("sans-serif", 14)).disable_mesh().draw()?;
        let step = 2.0 * e / cells as f32;
        chart.draw_series((0..cells * cells).map(|k| {
            let (x, z) = (at(k % cells), at(k / cells));
            let c = ViridisRGB::get_color_normalized(speed[k], 0.0, vmax);
            Rectangle::new([(x - 0.5 * step, z - 0.5 * step), (x + 0.5 * step, z + 0.5 * step)], c.filled())
        }))?;
        let cell = 2.0 * e / arrows as f32;
        for (k, s) in arrow_samples.iter().enumerate() {
            let h = glam::Vec2::new(av[k][0], av[k][2]);
            let len = h.length();
            if len < 1e-3 * vmax {
                continue;
            }
            let dir = h / len;
            let l = 0.45 * cell * (len / vmax).sqrt();
            let (x0, z0) = (s[0] - dir.x * l, s[2] - dir.y * l);
            let (x1, z1) = (s[0] + dir.x * l, s[2] + dir.y * l);
            let side = glam::Vec2::new(-dir.y, dir.x) * 0.3 * l;
            let back = glam::Vec2::new(x1, z1) - dir * 0.5 * l;
            chart.draw_series(std::iter::once(PathElement::new(vec![(x0, z0), (x1, z1)], WHITE.stroke_width(2))))?;
            chart.draw_series(std::iter::once(PathElement::new(
                vec![(back.x + side.x, back.y + side.y), (x1, z1), (back.x - side.x, back.y - side.y)],
                WHITE.stroke_width(2),
            )))?;
        }
        Ok(())
    })
}

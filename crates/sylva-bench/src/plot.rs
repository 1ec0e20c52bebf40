//! Log–log plots of a table's rows (plotters), with the font they are drawn in.

use anyhow::{Context, Result};
use plotters::prelude::*;
use std::path::Path;

/// DejaVu Sans (its license is beside it in `assets/`): the plots' and labels' font.
pub const FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Draws into a temporary PNG beside `path` ([`sylva_core::io::PendingFile`]), renamed into
/// place when complete: the plot is whole or absent.
pub fn atomic_png(
    path: &Path,
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>) -> Result<()>,
) -> Result<()> {
    pending_png(path, size, draw)?.commit().with_context(|| format!("writing {}", path.display()))
}

/// Draws into a temporary PNG beside `path` and returns it uncommitted, for outputs that
/// appear together: commit each once all are drawn.
pub fn pending_png(
    path: &Path,
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>) -> Result<()>,
) -> Result<sylva_core::io::PendingFile> {
    let pending = sylva_core::io::PendingFile::new(path).with_context(|| format!("writing {}", path.display()))?;
    {
        let root = BitMapBackend::new(pending.tmp(), size).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root)?;
        root.present().with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(pending)
}

/// Registers [`FONT`] as plotters' `sans-serif`.
pub fn register_font() {
    let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
}

/// A named, coloured series of (x, y) points.
pub type Series = (&'static str, RGBColor, Vec<(f64, f64)>);

/// A log–log line plot of `series`, written atomically to `path` (PNG).
pub fn plot_series(title: &str, x_desc: &str, y_desc: &str, series: Vec<Series>, path: &Path) -> Result<()> {
    register_font();
    atomic_png(path, (900, 600), |root| {
        let pts = series.iter().flat_map(|s| s.2.iter().copied());
        let (mut x_lo, mut x_hi, mut y_lo, mut y_hi) = (f64::INFINITY, 0.0f64, f64::INFINITY, 0.0f64);
        for (x, y) in pts {
            (x_lo, x_hi, y_lo, y_hi) = (x_lo.min(x), x_hi.max(x), y_lo.min(y), y_hi.max(y));
        }
        let (x_lo, x_hi) = (x_lo.min(x_hi).max(1e-9) * 0.7, x_hi.max(1.0) * 1.4);
        let (y_lo, y_hi) = (y_lo.min(y_hi).max(1e-6) * 0.5, y_hi.max(1e-3) * 2.0);
        let mut chart = ChartBuilder::on(root)
            .caption(title, ("sans-serif", 22))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d((x_lo..x_hi).log_scale(), (y_lo..y_hi).log_scale())?;
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc(y_desc)
            .x_label_formatter(&|x| format!("{x:.0}"))
            .y_label_formatter(&|y| if *y >= 10.0 { format!("{y:.0}") } else { format!("{y:.2}") })
            .draw()?;
        for (label, color, pts) in series {
            if pts.is_empty() {
                continue;
            }
            chart
                .draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))?
                .label(label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
            chart.draw_series(pts.iter().map(|&p| Circle::new(p, 4, color.filled())))?;
        }
        chart.configure_series_labels().border_style(BLACK).background_style(WHITE.mix(0.9)).draw()?;
        Ok(())
    })
}

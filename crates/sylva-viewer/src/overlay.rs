//! Drawn over the 3D view: the frame time, wind arrows on the ground, skeletons and HSM's
//! cluster centres, all from the world's overlay data.

use crate::camera::Orbit;
use crate::session::{Session, Stages};
use glam::Vec3;

/// Which overlays are on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Overlays {
    pub wind: bool,
    pub skeleton: bool,
    pub clusters: bool,
}

/// Frame time and counts over the view, then the overlays that are on.
pub(crate) fn draw(ui: &egui::Ui, rect: egui::Rect, s: &Session, orbit: &Orbit, stages: &Stages, on: Overlays) {
    let painter = ui.painter_at(rect);
    painter.text(
        rect.left_top() + egui::vec2(8.0, 6.0),
        egui::Align2::LEFT_TOP,
        format!(
            "{:.1} ms  ({:.0} fps)   t = {:.2} s{}",
            stages.frame,
            1e3 / stages.frame.max(1e-3),
            s.world.time(),
            if s.paused { "  paused" } else { "" }
        ),
        egui::FontId::monospace(13.0),
        egui::Color32::WHITE,
    );
    let aspect = rect.width() / rect.height().max(1.0);
    let vp = orbit.camera().view_proj(aspect);
    let project = |p: Vec3| -> Option<egui::Pos2> {
        let c = vp * p.extend(1.0);
        (c.w > 0.0).then(|| {
            let n = c.truncate() / c.w;
            egui::pos2(rect.left() + (n.x * 0.5 + 0.5) * rect.width(), rect.top() + (0.5 - n.y * 0.5) * rect.height())
        })
    };
    if on.wind {
        let stroke = egui::Stroke::new(1.5, egui::Color32::from_rgba_unmultiplied(255, 240, 120, 200));
        for (p, v) in s.world.wind_arrows(5) {
            if let (Some(a), Some(b)) = (project(p), project(p + v * 0.25)) {
                painter.arrow(a, b - a, stroke);
            }
        }
    }
    for i in 0..s.world.trees().len() {
        if on.clusters
            && let Ok(Some(centres)) = s.world.cluster_centres(i)
        {
            for c in centres {
                if let Some(p) = project(c) {
                    painter.circle_filled(p, 2.0, egui::Color32::from_rgb(90, 200, 255));
                }
            }
        }
        if on.skeleton
            && let Ok(bones) = s.world.skeleton(i)
        {
            let stroke = egui::Stroke::new(1.0, egui::Color32::from_rgb(255, 120, 60));
            for [a, b] in bones {
                if let (Some(a), Some(b)) = (project(a), project(b)) {
                    painter.line_segment([a, b], stroke);
                }
            }
        }
    }
}

//! The viewer's panel (egui): the scene and its errors, time, wind (the scene's fields,
//! an extra wind, what a click places), every tree's species, seed, method, backend and
//! forest size, overlays, and the frame's costs.

use crate::camera::Orbit;
use crate::overlay::Overlays;
use crate::script::Tool;
use crate::session::{Session, Stages};
use sylva_core::scene::BackendChoice;
use sylva_core::species::PRESETS;
use sylva_core::wind::{WindField, WindScene};

/// Largest forest the panel's slider makes, instances per tree.
const MAX_FOREST: usize = 5_000;

/// What the panel and the view ask for after the UI pass.
pub(crate) enum Action {
    /// A click at view point (u, v) with the current tool.
    Place(f32, f32),
    /// A push dragged from one view point to another.
    Push((f32, f32), (f32, f32)),
    /// Save the scene.
    Save,
}

/// The panel: scene, time, wind, trees, overlays and the frame's costs.
pub(crate) fn panel(
    ui: &mut egui::Ui,
    sim: &mut Session,
    orbit: &mut Orbit,
    stages: &Stages,
    overlays: &mut Overlays,
    status: &str,
    actions: &mut Vec<Action>,
) {
    ui.heading("Sylva");
    ui.label(sim.path.as_ref().map_or("built-in default scene".to_string(), |p| p.display().to_string()));
    if let Some(e) = &sim.reload_error {
        ui.colored_label(
            egui::Color32::from_rgb(230, 80, 70),
            format!("reload failed, still running the last good scene:\n{e}"),
        );
    }
    if let Some(e) = &sim.build_error {
        ui.colored_label(egui::Color32::from_rgb(230, 80, 70), e);
    }
    ui.horizontal(|ui| {
        if ui.button("Save scene").clicked() {
            actions.push(Action::Save);
        }
        if ui.button("Reset camera").clicked() {
            *orbit = Orbit::from_scene(sim.world.scene());
        }
    });
    if !status.is_empty() {
        ui.label(status);
    }
    ui.separator();
    ui.label(format!("t = {:.2} s", sim.world.time()));
    ui.horizontal(|ui| {
        ui.checkbox(&mut sim.paused, "pause");
        if ui.button("step").clicked() {
            sim.step_once = true;
        }
    });
    ui.add(egui::Slider::new(&mut sim.time_scale, 0.0..=4.0).text("time scale"));

    ui.separator();
    ui.strong("Wind");
    wind(ui, sim);

    ui.separator();
    ui.strong("Trees");
    for i in 0..sim.world.trees().len() {
        tree(ui, sim, i);
    }

    ui.separator();
    ui.strong("Overlays");
    ui.checkbox(&mut overlays.wind, "wind arrows");
    ui.checkbox(&mut overlays.skeleton, "skeleton (first instance of each tree)");
    ui.checkbox(&mut overlays.clusters, "HSM clusters (centres of mass)");
    ui.separator();
    ui.strong("Frame");
    ui.monospace(format!(
        "frame         {:6.1} ms\nsimulate      {:6.1} ms\n GPU sim+mesh {:6.1} ms\n GPU draw     {:6.1} ms\ndraw+present  {:6.1} ms\nui            {:6.1} ms",
        stages.frame, stages.simulate, stages.gpu_mesh, stages.gpu_draw, stages.draw, stages.ui
    ));
    let trees = sim.world.trees();
    let segments: usize = trees.iter().map(|e| e.tree.segments.len() * e.simulations).sum();
    let particles: usize = trees.iter().filter_map(|e| e.particles().map(|n| n * e.simulations)).sum();
    ui.monospace(format!(
        "{segments} segments simulated\n{particles} particles (HSM)\n{} triangles\n{} instances",
        sim.world.triangles(),
        sim.world.instances()
    ));
    ui.label(format!("GPU: {}", sim.ctx.summary.name));
}

/// The wind section: the scene's wind on or off, an extra constant wind, the scene's fields,
/// the tool a click uses.
fn wind(ui: &mut egui::Ui, sim: &mut Session) {
    let w = sim.world.wind();
    let (mut base_on, extra) = (w.base_on, w.extra);
    let mut changed = ui.checkbox(&mut base_on, format!("scene wind `{}`", sim.world.scene().wind)).changed();
    let mut on = extra.is_some();
    changed |= ui.checkbox(&mut on, "extra constant wind").changed();
    let (mut deg, mut speed) = extra.unwrap_or((0.0, 8.0));
    if on {
        changed |= ui.add(egui::Slider::new(&mut deg, -180.0..=180.0).text("direction °")).changed();
        changed |= ui.add(egui::Slider::new(&mut speed, 0.0..=40.0).text("speed m/s")).changed();
    }
    if changed {
        let r = sim.world.edit_wind(|w| {
            w.base_on = base_on;
            w.extra = on.then_some((deg, speed));
            true
        });
        sim.note(r);
    }
    let mut blend = sim.world.wind().wave_blend;
    if ui
        .add(egui::Slider::new(&mut blend, 0.0..=5.0).text("wave blend s"))
        .on_hover_text("an edit of the waves blends the old ones out, then the new ones in, over this time each")
        .changed()
    {
        let r = sim.world.edit_wind(|w| {
            w.wave_blend = blend;
            false
        });
        sim.note(r);
    }
    let mut edited = false;
    egui::CollapsingHeader::new("scene wind fields").show(ui, |ui| {
        let r = sim.world.edit_wind(|w| {
            edited = wind_fields(ui, &mut w.base);
            edited
        });
        sim.note(r);
    });
    sim.wind_edited |= edited;
    ui.horizontal(|ui| {
        ui.label("click places:");
        ui.radio_value(&mut sim.tool, Tool::Blast, "blast");
        ui.radio_value(&mut sim.tool, Tool::Vortex, "vortex");
        ui.radio_value(&mut sim.tool, Tool::Push, "push (drag)");
        ui.radio_value(&mut sim.tool, Tool::None, "nothing");
    });
    ui.add(egui::Slider::new(&mut sim.effect_strength, 2.0..=60.0).text("strength m/s"));
    let effects = sim.world.wind().effects().len();
    if effects > 0 && ui.button(format!("clear {effects} effect(s)")).clicked() {
        let r = sim.world.clear_effects();
        sim.note(r);
    }
}

/// Tree `i`: species, seed, method, backend and forest size; a change rebuilds it.
fn tree(ui: &mut egui::Ui, sim: &mut Session, i: usize) {
    let label = sim.world.trees()[i].label.clone();
    egui::CollapsingHeader::new(format!("{i}: {label}")).id_salt(("tree", i)).show(ui, |ui| {
        let mut st = sim.world.scene().trees[i].clone();
        let mut rebuild = false;
        egui::ComboBox::from_id_salt(("species", i)).selected_text(st.species.clone()).show_ui(ui, |ui| {
            for p in PRESETS {
                rebuild |= ui.selectable_value(&mut st.species, p.name.to_string(), p.name).changed();
            }
        });
        ui.horizontal(|ui| {
            ui.label("or file:");
            let edit = ui.add(egui::TextEdit::singleline(&mut st.species).desired_width(150.0));
            rebuild |= edit.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
        });
        ui.horizontal(|ui| {
            rebuild |= ui.add(egui::DragValue::new(&mut st.seed).prefix("seed ")).changed();
            if ui.button("new seed").clicked() {
                st.seed = st.seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407) >> 33;
                rebuild = true;
            }
        });
        ui.horizontal(|ui| {
            for m in sim.world.registry().names() {
                if ui.radio(st.method == m, m).clicked() && st.method != m {
                    st.method = sylva_core::scene::MethodName::new(m);
                    rebuild = true;
                }
            }
        });
        ui.horizontal(|ui| {
            for (b, name) in [(BackendChoice::Auto, "auto"), (BackendChoice::Cpu, "CPU"), (BackendChoice::Gpu, "GPU")] {
                rebuild |= ui.radio_value(&mut st.backend, b, name).changed();
            }
        });
        // Leaf motion: on or off, and its strength (the scene tree's `leaf_motion.strength`).
        let strength = st.leaf_motion.as_ref().and_then(|t| t.get("strength")).and_then(|v| v.as_float());
        let strength = strength.unwrap_or(1.0) as f32;
        let mut leaves_on = strength > 0.0;
        // The slider keeps the strength to come back to while leaf motion is off.
        let mut leaf_strength = if leaves_on { strength } else { 1.0 };
        ui.horizontal(|ui| {
            let toggled = ui.checkbox(&mut leaves_on, "leaf motion").changed();
            let slid = ui
                .add_enabled(leaves_on, egui::Slider::new(&mut leaf_strength, 0.05..=3.0).text("leaf strength"))
                .drag_stopped();
            if toggled || slid {
                let value = if leaves_on { leaf_strength } else { 0.0 };
                st.leaf_motion
                    .get_or_insert_with(Default::default)
                    .insert("strength".into(), toml::Value::Float(value as f64));
                rebuild = true;
            }
        });
        let mut n = if sim.forest[i] > 0 { sim.forest[i] } else { 1 + st.copies.len() };
        let forest =
            ui.add(egui::Slider::new(&mut n, 1..=MAX_FOREST).logarithmic(true).text("instances")).drag_stopped();
        if rebuild {
            sim.rebuild(i, |s| *s = st);
        } else if forest {
            sim.set_forest(i, n);
        }
        let e = &sim.world.trees()[i];
        ui.label(format!(
            "{} segments, {} leaves, {} triangles, {} instance(s), {} simulation(s)",
            e.tree.segments.len(),
            e.tree.leaves.len(),
            e.triangles,
            e.instances,
            e.simulations
        ));
    });
}

/// Sliders for the fields of the scene's wind; true when one moved.
fn wind_fields(ui: &mut egui::Ui, wind: &mut WindScene) -> bool {
    let mut changed = false;
    for (k, f) in wind.fields.iter_mut().enumerate() {
        ui.push_id(("field", k), |ui| match f {
            WindField::Constant(c) => {
                ui.label("constant");
                let mut deg = c.direction[2].atan2(c.direction[0]).to_degrees();
                if ui.add(egui::Slider::new(&mut deg, -180.0..=180.0).text("direction °")).changed() {
                    let a = deg.to_radians();
                    c.direction = [a.cos(), c.direction[1], a.sin()];
                    changed = true;
                }
                changed |= ui.add(egui::Slider::new(&mut c.speed, 0.0..=40.0).text("speed m/s")).changed();
            }
            WindField::SumOfSines(s) => {
                ui.label("sum of sines (Skjermo eqs. 11–14)");
                for (i, w) in s.waves.iter_mut().enumerate() {
                    ui.push_id(i, |ui| {
                        changed |=
                            ui.add(egui::Slider::new(&mut w.amplitude, 0.0..=10.0).text("amplitude m/s")).changed();
                        changed |= ui
                            .add(egui::Slider::new(&mut w.direction_deg, -180.0..=180.0).text("direction °"))
                            .changed();
                        changed |=
                            ui.add(egui::Slider::new(&mut w.wavelength, 1.0..=200.0).text("wavelength m")).changed();
                        changed |= ui.add(egui::Slider::new(&mut w.speed, 0.0..=20.0).text("speed m/s")).changed();
                    });
                }
            }
            WindField::Turbulence(t) => {
                ui.label("turbulence (1/f^β)");
                changed |= ui.add(egui::Slider::new(&mut t.intensity, 0.0..=8.0).text("gustiness (rms m/s)")).changed();
                changed |= ui.add(egui::Slider::new(&mut t.beta, 0.5..=3.0).text("β")).changed();
            }
            WindField::GustFront(g) => {
                ui.label("gust front");
                changed |= ui.add(egui::Slider::new(&mut g.strength, 0.0..=30.0).text("strength m/s")).changed();
                changed |=
                    ui.add(egui::Slider::new(&mut g.direction_deg, -180.0..=180.0).text("direction °")).changed();
            }
            WindField::Vortex(v) => {
                ui.label("vortex");
                changed |= ui.add(egui::Slider::new(&mut v.strength, -40.0..=40.0).text("strength m/s")).changed();
                changed |= ui.add(egui::Slider::new(&mut v.radius, 0.5..=40.0).text("radius m")).changed();
            }
            WindField::Blast(b) => {
                ui.label("blast");
                changed |= ui.add(egui::Slider::new(&mut b.strength, 0.0..=100.0).text("strength m/s")).changed();
            }
            WindField::Grid(g) => {
                let [nx, ny, nz] = g.data.size;
                ui.label(format!("grid {} ({nx}×{ny}×{nz}, {} frames)", g.file, g.data.frames));
                changed |= ui.add(egui::Slider::new(&mut g.scale, 0.0..=5.0).text("strength ×")).changed();
                changed |= ui.add(egui::Slider::new(&mut g.scroll[0], -20.0..=20.0).text("scroll x m/s")).changed();
                changed |= ui.add(egui::Slider::new(&mut g.scroll[2], -20.0..=20.0).text("scroll z m/s")).changed();
                changed |= ui.add(egui::Slider::new(&mut g.frame_rate, 0.0..=30.0).text("frames/s")).changed();
            }
        });
        ui.separator();
    }
    changed
}

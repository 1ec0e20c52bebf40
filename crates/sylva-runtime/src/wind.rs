//! A world's wind: the scene's fields (as loaded, or edited), an optional extra constant
//! wind, and live effects (blasts, vortices, pushes) placed while it runs, composed into one
//! scene. It is packed once per change and uploaded once per change into one buffer pair
//! on the device that every GPU method binds; CPU methods share the packed form.
//!
//! Phase groups run ahead of the scene's clock (their simulations started at different
//! points of the wind). A live effect placed at scene time t must reach every copy at t, so
//! a group with a lead sees the effects shifted onto its own clock: one more packed scene
//! and buffer pair per distinct lead, only while effects are live.
//!
//! An edit that changes the waves (sums of sines, turbulence) blends the old ones out, then
//! the new ones in, over [`WorldWind::wave_blend`] each (Skjermo §5: a wave whose parameters
//! change at once jumps the branches); the blends reach phase groups on their own clocks as
//! effects do.

use std::collections::BTreeMap;
use std::sync::Arc;
use sylva_core::wind::{Blast, Constant, Fade, GustFront, PackedWind, Vortex, WindField, WindScene};
use sylva_gpu::wind::GpuWind;
use sylva_gpu::{GpuContext, GpuError};

/// What a click or a drag places in the world.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Effect {
    /// An explosion at ground point (x, z): a shell of outward wind.
    Blast {
        /// Ground point (x, z), m.
        at: [f32; 2],
        /// Peak outward wind, m/s.
        strength: f32,
    },
    /// A whirlwind turning about a vertical axis at ground point (x, z).
    Vortex {
        /// Ground point (x, z), m.
        at: [f32; 2],
        /// Peak tangential wind, m/s.
        strength: f32,
    },
    /// A gust along the ground from `from` to `to` (x, z): stronger for a longer drag.
    Push {
        /// Start (x, z), m.
        from: [f32; 2],
        /// End (x, z), m.
        to: [f32; 2],
        /// Largest gust, m/s.
        strength: f32,
    },
}

impl Effect {
    /// The wind field of this effect, starting at scene time `t`; `None` for a push too short
    /// to have a direction.
    pub fn field(&self, t: f32) -> Option<WindField> {
        Some(match *self {
            Effect::Blast { at, strength } => WindField::Blast(Blast {
                centre: [at[0], 1.0, at[1]],
                strength,
                start: t,
                speed: 25.0,
                width: 6.0,
                decay: 1.2,
                radius: 40.0,
            }),
            Effect::Vortex { at, strength } => WindField::Vortex(Vortex {
                centre: at,
                drift: [0.0, 0.0],
                strength: 0.6 * strength,
                radius: 6.0,
                updraft: 0.1 * strength,
                start: t,
                duration: 6.0,
                fade: 1.0,
            }),
            Effect::Push { from, to, strength } => {
                let d = glam::Vec2::new(to[0] - from[0], to[1] - from[1]);
                let len = d.length();
                if len < 0.1 {
                    return None;
                }
                let dir = d / len;
                WindField::GustFront(GustFront {
                    origin: [from[0] - 4.0 * dir.x, from[1] - 4.0 * dir.y],
                    direction_deg: dir.y.atan2(dir.x).to_degrees(),
                    strength: (2.0 * len).clamp(4.0, strength.max(4.0)),
                    speed: 12.0,
                    width: 3.0,
                    length: 6.0 + len,
                    radius: 5.0,
                    start: t,
                })
            }
        })
    }
}

/// Whether a live effect is still blowing at scene time `t`.
fn alive(f: &WindField, t: f32) -> bool {
    match f {
        WindField::Blast(b) => t < b.start + 8.0 * b.decay + b.radius / b.speed.max(1.0),
        WindField::Vortex(v) => t < v.start + v.duration + v.fade,
        WindField::GustFront(g) => t < g.start + 4.0,
        _ => true,
    }
}

/// The wind of one clock (the scene's, or a phase group's lead), packed and on the device.
#[derive(Debug, Clone)]
pub(crate) struct ClockWind {
    pub(crate) packed: Arc<PackedWind>,
    pub(crate) gpu: GpuWind,
}

/// A world's wind (see the module docs).
#[derive(Debug)]
pub struct WorldWind {
    /// The scene's own fields, as loaded or edited.
    pub base: WindScene,
    /// Whether the scene's fields blow.
    pub base_on: bool,
    /// An extra constant wind: direction (degrees from +X toward +Z) and speed (m/s).
    pub extra: Option<(f32, f32)>,
    /// Seconds an edit takes to blend the old waves out, and again the new ones in.
    /// Default 1 s: longer than a branch's period (under 1 s for trees over ~4 m), so the
    /// wind's change is slow to the wood. 0 switches at once.
    pub wave_blend: f32,
    effects: Vec<WindField>,
    /// The steady wind as it blows: the scene's and the extra wind with the blends of edits
    /// in progress ([`WindScene::blend_waves`]).
    blowing: WindScene,
    /// Which of `blowing`'s fields carry a blend made by an edit.
    blended: Vec<bool>,
    composed: WindScene,
    scene_clock: ClockWind,
    /// Per lead (its bits): the scene with the effects shifted onto that clock.
    leads: BTreeMap<u32, ClockWind>,
}

impl WorldWind {
    /// The scene's wind, uploaded.
    pub fn new(ctx: &GpuContext, base: WindScene) -> Result<Self, GpuError> {
        let packed = Arc::new(base.packed());
        let gpu = GpuWind::new(ctx, packed.clone())?;
        Ok(Self {
            blended: vec![false; base.fields.len()],
            blowing: base.clone(),
            composed: base.clone(),
            base,
            base_on: true,
            extra: None,
            wave_blend: 1.0,
            effects: Vec::new(),
            scene_clock: ClockWind { packed, gpu },
            leads: BTreeMap::new(),
        })
    }

    /// Everything that blows, on the scene's clock.
    pub fn composed(&self) -> &WindScene {
        &self.composed
    }

    /// The composed scene packed (what CPU methods and overlays sample).
    pub fn packed(&self) -> &Arc<PackedWind> {
        &self.scene_clock.packed
    }

    /// The live effects.
    pub fn effects(&self) -> &[WindField] {
        &self.effects
    }

    /// The wind for a simulation whose clock runs `lead` seconds ahead of the scene's.
    pub(crate) fn clock(&mut self, ctx: &GpuContext, lead: f32) -> Result<ClockWind, GpuError> {
        if lead == 0.0 || (self.effects.is_empty() && !self.blended.contains(&true)) {
            return Ok(self.scene_clock.clone());
        }
        if let Some(c) = self.leads.get(&lead.to_bits()) {
            return Ok(c.clone());
        }
        let mut w = self.blowing.clone();
        for (f, _) in w.fields.iter_mut().zip(&self.blended).filter(|(_, b)| **b) {
            if let Some((fade_in, fade_out)) = f.fades() {
                let shift = |f: Option<Fade>| f.map(|f| Fade { start: f.start + lead, ..f });
                f.set_fades(shift(fade_in), shift(fade_out));
            }
        }
        w.fields.extend(self.effects.iter().cloned().map(|mut f| {
            match &mut f {
                WindField::Blast(b) => b.start += lead,
                WindField::Vortex(v) => v.start += lead,
                WindField::GustFront(g) => g.start += lead,
                _ => {}
            }
            f
        }));
        let packed = Arc::new(w.packed());
        let c = ClockWind { gpu: GpuWind::new(ctx, packed.clone())?, packed };
        self.leads.insert(lead.to_bits(), c.clone());
        Ok(c)
    }

    /// The scene's and the extra wind, without the effects.
    fn steady(&self) -> WindScene {
        let mut fields = if self.base_on { self.base.fields.clone() } else { Vec::new() };
        if let Some((deg, speed)) = self.extra {
            let a = deg.to_radians();
            fields.push(WindField::Constant(Constant { direction: [a.cos(), 0.0, a.sin()], speed }));
        }
        WindScene { fields }
    }

    /// Recomposes and re-uploads after any change of `base`, `base_on`, `extra` or the
    /// effects. With `blend_at`, changed waves blend from that scene time on
    /// ([`Self::wave_blend`]); without, the steady wind is replaced at once.
    pub(crate) fn recompose(&mut self, ctx: &GpuContext, blend_at: Option<f32>) -> Result<(), GpuError> {
        let next = self.steady();
        self.blowing = match blend_at {
            Some(at) => self.blowing.blend_waves(&next, at, self.wave_blend),
            None => next.clone(),
        };
        self.blended = self.blowing.fields.iter().enumerate().map(|(i, f)| next.fields.get(i) != Some(f)).collect();
        let mut w = self.blowing.clone();
        w.fields.extend(self.effects.iter().cloned());
        let packed = Arc::new(w.packed());
        self.scene_clock.gpu.update(ctx, packed.clone())?;
        self.scene_clock.packed = packed;
        self.composed = w;
        self.leads.clear();
        Ok(())
    }

    /// Adds a live effect.
    pub(crate) fn push_effect(&mut self, field: WindField) {
        self.effects.push(field);
    }

    /// Removes every live effect.
    pub(crate) fn clear_effects(&mut self) {
        self.effects.clear();
    }

    /// Drops the effects that are over at scene time `t`, and the waves blended out by then
    /// (they would still cost a term per sample); true when any was.
    pub(crate) fn expire(&mut self, t: f32) -> bool {
        let before = (self.effects.len(), self.blowing.fields.len());
        self.effects.retain(|f| alive(f, t));
        let fields = std::mem::take(&mut self.blowing.fields).into_iter().zip(std::mem::take(&mut self.blended));
        (self.blowing.fields, self.blended) = fields.filter(|(f, _)| !f.faded_out(t)).unzip();
        (self.effects.len(), self.blowing.fields.len()) != before
    }

    /// The steady wind as it blows now: the scene's and the extra wind, with the blends of
    /// edits in progress.
    pub fn blowing(&self) -> &WindScene {
        &self.blowing
    }
}

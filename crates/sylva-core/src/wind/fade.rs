//! Blending wave fields in and out (Skjermo §5): a [`Fade`] scales a sum of sines' or a
//! turbulence field's waves by a smoothstep, and [`WindScene::blend_waves`] goes from one
//! scene to the next by blending the old waves out, then the new ones in, since a wave whose
//! parameters change at once jumps the branches. Sampled by `wind::sample::wave_envelope`
//! (and its WGSL twin) from the packed [`Fade::envelope`].

use super::{WindField, WindScene};
use serde::{Deserialize, Serialize};

/// A wave field's blend in or out: its amplitude follows a smoothstep from `start` to
/// `start + duration` (C¹, so the wind's rate of change never jumps).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fade {
    /// Scene time the blend starts, s.
    pub start: f32,
    /// Length of the blend, s (at least 1 ms).
    pub duration: f32,
}

impl Fade {
    /// The packed envelope of a wave field (`RawField::b`): `[in start, 1 / in duration,
    /// out start, 1 / out duration]`, ±1e30 where absent, so the envelope is exactly 1 there.
    pub fn envelope(fade_in: Option<Fade>, fade_out: Option<Fade>) -> [f32; 4] {
        let (i, o) = (
            fade_in.unwrap_or(Fade { start: -1e30, duration: 1.0 }),
            fade_out.unwrap_or(Fade { start: 1e30, duration: 1.0 }),
        );
        [i.start, 1.0 / i.duration, o.start, 1.0 / o.duration]
    }

    /// When the blend is over, s.
    pub fn end(&self) -> f32 {
        self.start + self.duration
    }
}

impl WindField {
    /// The fades of a wave field (sum of sines, turbulence); `None` for other kinds.
    pub fn fades(&self) -> Option<(Option<Fade>, Option<Fade>)> {
        match self {
            WindField::SumOfSines(s) => Some((s.fade_in, s.fade_out)),
            WindField::Turbulence(t) => Some((t.fade_in, t.fade_out)),
            _ => None,
        }
    }

    /// Sets a wave field's fades (other kinds are left as they are).
    pub fn set_fades(&mut self, fade_in: Option<Fade>, fade_out: Option<Fade>) {
        match self {
            WindField::SumOfSines(s) => (s.fade_in, s.fade_out) = (fade_in, fade_out),
            WindField::Turbulence(t) => (t.fade_in, t.fade_out) = (fade_in, fade_out),
            _ => {}
        }
    }

    /// Whether the field is silent from `t` on (a wave field whose fade-out is over).
    pub fn faded_out(&self, t: f32) -> bool {
        matches!(self.fades(), Some((_, Some(out))) if t >= out.end())
    }
}

impl WindScene {
    /// The scene that goes from `self` to `next` at time `at` as Skjermo §5 asks: `next`'s
    /// other fields at once, `self`'s wave fields that `next` lacks blended out over
    /// `[at, at + duration]`, then `next`'s new wave fields blended in over the same length
    /// (at once where nothing goes out), so no wave's parameters jump. Wave fields in both
    /// (the same waves and fade-out) are kept as they are, in progress; old ones not yet in
    /// at `at` are dropped (so a slider dragged through many edits keeps one set going out and
    /// one coming in). The first
    /// `next.fields.len()` fields stand for `next`'s, in order; the outgoing ones follow.
    /// `duration ≤ 0` (or not finite) gives `next` as it is.
    pub fn blend_waves(&self, next: &WindScene, at: f32, duration: f32) -> WindScene {
        if !duration.is_finite() || duration <= 0.0 {
            return next.clone();
        }
        let bare = |f: &WindField| {
            let mut f = f.clone();
            f.set_fades(None, None);
            f
        };
        let same =
            |a: &WindField, b: &WindField| bare(a) == bare(b) && a.fades().map(|f| f.1) == b.fades().map(|f| f.1);
        let mut kept = vec![false; self.fields.len()];
        let mut fields = Vec::with_capacity(next.fields.len());
        let mut incoming = Vec::new();
        for f in &next.fields {
            if f.fades().is_none() {
                fields.push(f.clone());
                continue;
            }
            match (0..self.fields.len()).find(|&k| !kept[k] && same(&self.fields[k], f)) {
                Some(k) => {
                    kept[k] = true;
                    fields.push(self.fields[k].clone());
                }
                None => {
                    incoming.push(fields.len());
                    fields.push(f.clone());
                }
            }
        }
        let out = Fade { start: at, duration };
        let mut outgoing = Vec::new();
        for (k, f) in self.fields.iter().enumerate() {
            let Some((fade_in, fade_out)) = f.fades() else { continue };
            // Gone already, or not yet in (a blend that an edit in the middle overtakes).
            let silent = fade_in.is_some_and(|i| i.start >= at);
            if kept[k] || f.faded_out(at) || silent {
                continue;
            }
            let mut f = f.clone();
            let sooner = fade_out.filter(|o| o.end() <= out.end());
            f.set_fades(fade_in, Some(sooner.unwrap_or(out)));
            outgoing.push(f);
        }
        let start = if outgoing.is_empty() { at } else { at + duration };
        for &i in &incoming {
            let (fade_in, fade_out) = fields[i].fades().unwrap_or_default();
            let later = fade_in.filter(|f| f.start >= start);
            fields[i].set_fades(Some(later.unwrap_or(Fade { start, duration })), fade_out);
        }
        fields.extend(outgoing);
        WindScene { fields }
    }
}

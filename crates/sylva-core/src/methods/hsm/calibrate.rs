//! Tuning HSM to the wood. Shape matching gives each cluster a rate (1/s²), not a modulus,
//! and a chain of clusters held through ring levers is stiffer than the beam it stands for
//! (and, where it is stiffer than the substep, held by the hold instead). So the method
//! measures its own trunk once: a lateral load switched on at rest in still air, no damping
//! and no drag, swings the trunk top to its first peak after half a period. Every rate
//! scales the dynamics' frequencies by its square root (the hold scales with them), so one
//! measurement gives the factor that puts the trunk at its first mode from the wood.

use super::{FIXED, Hsm};
use crate::model::{NONE, Tree};

/// Lateral acceleration of the pluck, m/s² (the dynamics are linear in it but for large
/// bends; 1 m/s² bends a tree by a small fraction of the wind's).
const LOAD: f32 = 1.0;

/// Longest pluck simulated, s: a trunk slower than 1/(2 · 20 s) is left uncalibrated.
const LONGEST: f32 = 20.0;

/// The trunk's first-mode frequency under `hsm`'s own dynamics at its substep rate, Hz:
/// half the inverse of the time the trunk top's tail ring takes to reach its first peak
/// after a step load. `None` without a substep rate, without a trunk cluster, or when no
/// peak comes within `LONGEST` seconds.
pub fn trunk_frequency(tree: &Tree, hsm: &Hsm) -> Option<f32> {
    let rate = hsm.params.substep_rate;
    if rate <= 0.0 {
        return None;
    }
    let top = (tree.stems.first_segment[0] + tree.stems.segment_count[0] - 1) as usize;
    let c = hsm.layout.segment_cluster[top];
    if c == NONE {
        return None;
    }
    let info = hsm.layout.info[c as usize];
    let k = hsm.params.ring_size.min(info.slot_count);
    let end = (info.slot_offset + info.slot_count) as usize;
    let ring: Vec<usize> = hsm.layout.slots[end - k as usize..end].iter().map(|s| s.particle as usize).collect();
    let mut state = hsm.state_at_rest();
    for v in &mut state.velocity {
        if v[3] != FIXED {
            v[3] = 0.0;
        }
    }
    let h = 1.0 / rate;
    let mut step = hsm.step_params(0.0, h);
    step.gravity = [LOAD, 0.0, 0.0, 0.0];
    step.damping = 1.0;
    let mut x: Vec<f32> = Vec::new();
    let (mut best, mut at) = (0.0f32, 0usize);
    for i in 0..(LONGEST * rate) as usize {
        step.time = (i + 1) as f32 * h;
        hsm.substep_with(&[], &[], &mut state, step);
        let xi = ring.iter().map(|&p| state.displacement[p][0]).sum::<f32>() / ring.len() as f32;
        if !xi.is_finite() {
            return None;
        }
        x.push(xi);
        if xi > best {
            (best, at) = (xi, i);
        } else if best > 0.0 && xi < 0.5 * best {
            // Past the first peak: refine it on the parabola through its neighbours.
            let (a, b, c) = (x[at.saturating_sub(1)] as f64, best as f64, x[at + 1] as f64);
            let curve = a - 2.0 * b + c;
            let shift = if at > 0 && curve < 0.0 { (0.5 * (a - c) / curve).clamp(-0.5, 0.5) } else { 0.0 };
            let peak = (at as f64 + 1.0 + shift) * h as f64;
            return Some((0.5 / peak) as f32);
        }
    }
    None
}

//! Tuning HSM to the wood. Shape matching gives each cluster a rate (1/s²), not a modulus,
//! and a chain of clusters held through ring levers is stiffer than the beam it stands for
//! (and, where it is stiffer than the substep, held by the hold instead). So the method
//! measures its own stems once, in still air without damping or drag, and scales their
//! rates until each rings at its first mode from the wood,
//! [`crate::physics::stem_frequencies`], then its drag until the trunk leans as the beam.
//!
//! Scaling every rate and the hold by `s` scales every frequency of the dynamics by `√s`,
//! so the stems are plucked as built and compared with their targets times the trunk's
//! `ratio` (its frequency as built over its target); one scale by `1 / ratio²` at the end
//! puts them all where they belong, and no pluck runs at the slower calibrated pace.
//! 1. The trunk: a lateral load switched on at rest swings its top to its first peak after
//!    half a period ([`trunk_frequency`]).
//! 2. Every level of side stems, deepest first (a stem carries its children): the levels
//!    below are held at rest, as the beam model clamps a stem at its base, and each stem is
//!    set moving across its axis with all it carries; its tip reaches its first peak after a
//!    quarter period ([`side_stem_frequencies`]). Each stem's clusters get their own factor.
//!    One scale for the whole tree left the aspen's branches and twigs at about half their
//!    beam frequency: a chain of a few short clusters stands for its beam differently from
//!    the trunk's long one. Last, the stems a forked trunk grows on its own level
//!    (Weber–Penn's clones, the leaders of the black oak's crown), the trunk held.
//! 3. The trunk again: stiffer side stems hold more of the crown's mass to it (and weigh
//!    more on the rings they share with it), so its own clusters are scaled back to the
//!    frequency of step 1, and again while it is more than 2 % off and each pass at least
//!    halves what is left (at most three passes).
//! 4. The drag: a steady calm wind switched on at rest swings the trunk's end in the pose,
//!    where the tree is drawn, about its lean, its mean over two periods of the trunk
//!    (`LEAN_PERIODS`), which the final scale divides by `1 / ratio²`; every particle's
//!    drag is scaled so that lean is the beam's under the same (sheltered) drag,
//!    [`crate::physics::beam::drag_bend`]. Rigid clusters ring as their beam does once
//!    scaled, but a spread load bends them otherwise: by 11× too little on the aspen (a long
//!    trunk of short, thick segments), by 2× on the palm (its mass in the crown).
//! 5. A forked trunk's leaders, which those loads bend far more than their beams: on the
//!    black oak at its mean size (11.7 m) the drag that leans the trunk as its beam leaned
//!    its eleven other leaders' tops 7 times as far as its own (12.0 against 1.72 % of the
//!    height in a steady 6 m/s wind), and the crown swung as one at half the trunk's
//!    frequency. Each leader, the trunk held, is set leaning under those loads as step 4
//!    sets the trunk, each end read from its own clusters' turns ([`side_stem_leans`]),
//!    and its rates scaled by its lean over its beam's, so it leans as its beam does; then
//!    one pass of step 3 and step 4 again. Its own ring, with the trunk held, quickens by
//!    the root of that factor (at most `STEM_FACTOR`'s 16, which all but two of the oak's
//!    leaders reach), but held by the trunk it rings with the tree: the oak's leaders'
//!    tops lean 1.69 % against the trunk's 1.67 %, and after the wind stops their mean
//!    rings at 0.85 Hz against the trunk's 0.865 Hz from the wood.
//! 6. The air's damping ([`air_scale`]): the hold moves a held ring as if it were heavier
//!    (`Σ w / hold` times), so the trunk's mode carries its inertia where the rings are
//!    held, while the drag damps where its area is. On the small aspen (6 m) that weighs
//!    the mode's inertia 32 times the wood's and the drag's damping 9 times (the leaves
//!    ride on twigs the hold keeps less), and the trunk rang at 0.25 of the air's damping
//!    of the beam; on a bare uniform cantilever both weigh alike. The air's damping is
//!    scaled by the ratio, so the trunk's mode meets the air as the particles' own masses
//!    would.

use super::raw::kind;
use super::{FIXED, Hsm};
use crate::model::{NONE, Tree};
use glam::{Quat, Vec3};

/// The trunk's stem: plucked on its own (steps 1 and 3), and held while the stems of its
/// level that its forks grow (Weber–Penn's clones) are plucked as side stems (step 2).
const TRUNK: usize = 0;

/// Lateral acceleration of the pluck, m/s² (the dynamics are linear in it but for large
/// bends; 1 m/s² bends a tree by a small fraction of the wind's).
const LOAD: f32 = 1.0;

/// Longest pluck simulated, s: a trunk slower than 1/(2 · 20 s) is left uncalibrated.
const LONGEST: f32 = 20.0;

/// Longest trunk pluck as built, in periods of the trunk's target: a trunk 32 times slower
/// than its mode from the wood (or one whose top never falls back from its first peak) is
/// left as built.
const FIRST: f32 = 16.0;

/// The trunk top's first peak is read once it falls back below this fraction of it. A
/// step load on a lone mode swings the top to twice its lean and back to rest, but a short,
/// thick bole under a spreading crown hands its swing to the crown's branches: the black
/// oak's top falls from its peak to 0.57 of it and then hovers about 0.7, and the willow's
/// (with its source's split trunk) to 0.76; with 0.5 neither tree was calibrated. Every
/// preset whose top does fall to half (no earlier dip of 15 %) is read at the same peak with
/// either fraction.
const DROP: f32 = 0.85;

/// Longest trunk pluck after the side stems are scaled, in periods as built: a trunk that
/// slows by more than 8 times is left so.
const AGAIN: f32 = 4.0;

/// Most times the trunk is brought back after the side stems are scaled (step 3). One pass
/// left the half-size aspen's trunk (its leaves' mass on its twigs) at 0.90 of step 1's
/// frequency, the full-size aspen's at 0.97, the fir's at 0.95; a second pass brings them
/// to 0.99.
const TRUNK_PASSES: usize = 3;

/// A trunk within this fraction of step 1's frequency after a pass is left so.
const TRUNK_TOLERANCE: f32 = 0.02;

/// Wind speed of the static pluck, m/s (small: the bend is linear in the drag).
const CALM: f32 = 1.0;

/// Length of the static pluck in periods of the trunk as built: the mean of `1 − cos ωt`
/// over two periods of the trunk's mode is its lean, and a quicker mode's swing averages to
/// within `1 / (4π)` of it.
const LEAN_PERIODS: f32 = 2.0;

/// Bounds of the factor on the drag that gives the calibrated trunk the beam's static bend.
const LOAD_FACTOR: (f32, f32) = (1.0 / 64.0, 64.0);

/// Speed a side stem is set moving at, m/s (small: the dynamics are linear in it).
const SPEED: f32 = 0.01;

/// Bounds of a stem's own factor on its rates: a stem that the hold keeps from following
/// its rate is not stiffened without end, and one that misses its peak (read at the deadline)
/// gets the bound.
const STEM_FACTOR: (f32, f32) = (1.0 / 16.0, 16.0);

/// The trunk's first-mode frequency under `hsm`'s own dynamics at its substep rate, Hz:
/// half the inverse of the time the trunk top's tail ring takes to reach its first peak
/// after a step load. `None` without a substep rate, without a trunk cluster, or when no
/// peak comes within `LONGEST` seconds.
pub fn trunk_frequency(tree: &Tree, hsm: &Hsm) -> Option<f32> {
    trunk_pluck(tree, hsm, LONGEST)
}

/// [`trunk_frequency`], giving up after `longest` seconds.
fn trunk_pluck(tree: &Tree, hsm: &Hsm, longest: f32) -> Option<f32> {
    let (mut best, mut at) = (0.0f32, 0usize);
    trunk_run(tree, hsm, longest, None, Top::Ring, |x, h, _| {
        let (i, xi) = (x.len() - 1, x[x.len() - 1]);
        if xi > best {
            (best, at) = (xi, i);
        } else if best > 0.0 && xi < DROP * best {
            return Some(0.5 / refine(x, at, h));
        }
        None
    })
}

/// The trunk top's static lean under the drag of a steady wind of `speed` m/s along x, m:
/// the mean displacement of its end in the pose ([`Top::Pose`]) over `window` seconds from
/// rest (quadratic drag, without the air's damping or reconfiguration: a step load,
/// undamped), and each particle's mean x displacement over the same run, the lean's shape.
/// A lone mode swings about its lean as `1 − cos ωt`, whose mean over whole
/// periods is the lean; the first peak, twice the lean for a lone mode, is a crown's own
/// quicker swing where the trunk hands its load to heavy leaders (on the black oak's sapling
/// with forks that share the section, half that peak was a 194th of the lean).
fn static_lean(tree: &Tree, hsm: &Hsm, window: f32, speed: f32) -> Option<(f32, Vec<f32>)> {
    let mut shape = vec![0.0f64; hsm.layout.rest.len()];
    trunk_run(tree, hsm, window, Some(speed), Top::Pose, |x, h, state| {
        for (sum, u) in shape.iter_mut().zip(&state.displacement) {
            *sum += u[0] as f64;
        }
        ((x.len() + 1) as f32 * h > window).then(|| {
            let n = x.len() as f64;
            let lean = x.iter().map(|&v| v as f64).sum::<f64>() / n;
            (lean as f32, shape.iter().map(|s| (s / n) as f32).collect())
        })
    })
}

/// Where a trunk run reads the trunk top's x displacement.
#[derive(Clone, Copy)]
enum Top {
    /// The mean of the particles of the tail ring of the trunk's last cluster.
    Ring,
    /// The end of the trunk's last segment in the pose, each segment from the root turned by
    /// its cluster's rotation ([`Method::pose`](crate::methods::Method::pose)): where the
    /// tree is drawn. Clusters also move their particles across the axis without turning:
    /// on the black oak's sapling (forks that share the section) the ring leans 1.2–1.6
    /// times as far as the pose in a steady wind, and a drag scaled on the ring left the drawn
    /// tree leaning 0.55 of its beam (the other presets' drag scales moved 2–15 %).
    Pose,
}

/// A stem's clusters from its end to its base, each with its vector at rest ([`stem_chain`]).
type Chain = Vec<(usize, Vec3)>;

/// Each segment of stem `k` with a cluster, from its end to its base, and its vector at rest
/// to the next joint on the way (the stem's end for the last): with the stem's base held,
/// the pose puts its end at `Σ (R − 1) v` from rest. The trunk's run to the root.
fn stem_chain(tree: &Tree, hsm: &Hsm, k: usize) -> Chain {
    let s = &tree.segments;
    let mut chain = Vec::new();
    if tree.stems.segment_count[k] == 0 {
        return chain;
    }
    let mut i = (tree.stems.first_segment[k] + tree.stems.segment_count[k] - 1) as usize;
    let mut next = s.end(i);
    loop {
        let c = hsm.layout.segment_cluster[i];
        if c != NONE {
            chain.push((c as usize, next - s.start[i]));
        }
        next = s.start[i];
        match s.parent[i] {
            p if p == NONE || s.stem[p as usize] as usize != k => return chain,
            p => i = p as usize,
        }
    }
}

/// The substep rate the calibration steps `hsm` at, Hz: the one its rates as they stand need
/// ([`super::HsmParams::substep_rate`], quickened by the root of the rate scale above 1).
fn substep_rate(hsm: &Hsm) -> f32 {
    hsm.params.substep_rate * hsm.layout.rate_scale.max(1.0).sqrt()
}

/// The end of a chain from [`stem_chain`] in the pose, displaced from rest.
fn chain_end(chain: &[(usize, Vec3)], state: &super::HsmState) -> Vec3 {
    chain.iter().map(|&(c, v)| Quat::from_array(state.clusters[c].rotation) * v - v).sum()
}

/// Steps `hsm` from rest under `LOAD` (`speed` `None`) or under the drag of a steady wind of
/// `speed` m/s along x, for at most `longest` seconds, handing the trunk top's x
/// displacement so far, read `at` it (one entry per substep), the substep and the state to
/// `read` after each substep until it answers. `None` without a substep rate, without a trunk
/// cluster, on a non-finite displacement, or when `read` has not answered in time.
fn trunk_run<T>(
    tree: &Tree,
    hsm: &Hsm,
    longest: f32,
    speed: Option<f32>,
    at: Top,
    mut read: impl FnMut(&[f32], f32, &super::HsmState) -> Option<T>,
) -> Option<T> {
    let rate = substep_rate(hsm);
    if rate <= 0.0 || tree.stems.is_empty() {
        return None;
    }
    let ring = tip_ring(tree, hsm, 0)?;
    let chain = stem_chain(tree, hsm, TRUNK);
    let mut state = hsm.state_at_rest();
    if speed.is_none() {
        // No drag (the velocity's w is the particle's drag factor).
        for v in &mut state.velocity {
            if v[3] != FIXED {
                v[3] = 0.0;
            }
        }
    }
    let h = 1.0 / rate;
    let mut step = hsm.step_params(0.0, h);
    step.gravity = [LOAD, 0.0, 0.0, 0.0];
    step.damping = 1.0;
    let wind = speed.map(|speed| {
        step.gravity = [0.0; 4];
        (step.air, step.vogel_exponent, step.leaf_turbulence) = (0.0, 0.0, 0.0);
        let field = crate::wind::WindField::Constant(crate::wind::Constant { direction: [1.0, 0.0, 0.0], speed });
        crate::wind::WindScene { fields: vec![field] }.packed()
    });
    let (fields, waves) = wind.as_ref().map_or((&[][..], &[][..]), |w| (&w.fields[..], &w.waves[..]));
    let mut x: Vec<f32> = Vec::new();
    for i in 0..(longest.min(LONGEST) * rate) as usize {
        step.time = (i + 1) as f32 * h;
        step.sample_wind = (i == 0) as u32;
        hsm.substep_with(fields, waves, &mut state, step);
        let xi = match at {
            Top::Ring => ring.iter().map(|&p| state.displacement[p][0]).sum::<f32>() / ring.len() as f32,
            Top::Pose => chain_end(&chain, &state).x,
        };
        if !xi.is_finite() {
            return None;
        }
        x.push(xi);
        if let Some(v) = read(&x, h, &state) {
            return Some(v);
        }
    }
    None
}

/// The side stems of `level` (the trunk's own level: the stems its forks grow) as the
/// calibration moves them, with the levels below and the trunk held: the stem of `level`
/// that carries each stem of the tree (`NONE` for a held one), and the direction each stem
/// of `level` is moved in, horizontal and square to its axis (along x for an upright stem;
/// zero for the others and for stems without segments).
fn carriers(tree: &Tree, level: u8) -> (Vec<u32>, Vec<Vec3>) {
    let st = &tree.stems;
    let mut carrier = vec![NONE; st.len()];
    let mut push = vec![Vec3::ZERO; st.len()];
    for k in 0..st.len() {
        carrier[k] = if k == TRUNK {
            NONE
        } else if st.level[k] == level {
            k as u32
        } else if st.level[k] > level && st.parent[k] != NONE && (st.parent[k] as usize) < k {
            carrier[st.parent[k] as usize]
        } else {
            NONE
        };
        if carrier[k] == k as u32 && st.segment_count[k] > 0 {
            let first = st.first_segment[k] as usize;
            let last = first + st.segment_count[k] as usize - 1;
            let axis = (tree.segments.end(last) - tree.segments.start[first]).normalize_or_zero();
            let across = axis.cross(Vec3::Y);
            push[k] = if across.length() > 0.1 { across.normalize() } else { Vec3::X };
        }
    }
    (carrier, push)
}

/// The stem cluster `c` belongs to (a leaf's: its segment's).
fn cluster_stem(tree: &Tree, hsm: &Hsm, c: usize) -> usize {
    let info = hsm.layout.info[c];
    (match info.kind {
        kind::SEGMENT => tree.segments.stem[info.source as usize],
        kind::LEAF => tree.segments.stem[tree.leaves.segment[info.source as usize] as usize],
        _ => info.source,
    }) as usize
}

/// The first-mode frequency of every stem of `level` under `hsm`'s dynamics, Hz, with the
/// levels below and the trunk held at rest: one entry per stem of the tree, `None` for the
/// trunk, the other levels and stems the layout has no cluster for. Each stem, with all it
/// carries, is set moving across its axis at rest ([`carriers`]) and its tip ring reaches
/// its first peak after a quarter period. A stem still rising after `deadline(stem)` seconds
/// reads as that long a quarter period.
pub fn side_stem_frequencies(tree: &Tree, hsm: &Hsm, level: u8, deadline: impl Fn(usize) -> f32) -> Vec<Option<f32>> {
    let (st, l) = (&tree.stems, &hsm.layout);
    let (mut out, rate) = (vec![None; st.len()], substep_rate(hsm));
    if rate <= 0.0 {
        return out;
    }
    let (carrier, push) = carriers(tree, level);
    // Each stem's tip ring.
    let mut probes: Vec<(usize, Vec<usize>, f32)> = Vec::new();
    for k in (0..st.len()).filter(|&k| push[k] != Vec3::ZERO) {
        if let Some(ring) = tip_ring(tree, hsm, k) {
            probes.push((k, ring, deadline(k)));
        }
    }
    let mut state = hsm.state_at_rest();
    for (p, v) in state.velocity.iter_mut().enumerate() {
        if v[3] == FIXED {
            continue;
        }
        let k = carrier[cluster_stem(tree, hsm, l.owner[p] as usize)];
        if k == NONE {
            v[3] = FIXED;
        } else {
            let w = push[k as usize] * SPEED;
            *v = [w.x, w.y, w.z, 0.0];
        }
    }
    let h = 1.0 / rate;
    let longest = probes.iter().map(|p| p.2).fold(0.0f32, f32::max).min(LONGEST);
    let mut x: Vec<Vec<f32>> = vec![Vec::new(); probes.len()];
    let mut best = vec![(0.0f32, 0usize); probes.len()];
    let mut done = vec![false; probes.len()];
    let mut open = probes.len();
    held_run(hsm, &mut state, hsm.step_params(0.0, h), (longest * rate).ceil() as usize, |state, i, time| {
        for (q, (k, ring, until)) in probes.iter().enumerate() {
            if done[q] {
                continue;
            }
            let d = ring.iter().map(|&p| Vec3::from_slice(&state.displacement[p][..3])).sum::<Vec3>();
            let xi = d.dot(push[*k]) / ring.len() as f32;
            if !xi.is_finite() {
                (done[q], open) = (true, open - 1);
                continue;
            }
            x[q].push(xi);
            let (b, at) = &mut best[q];
            if xi > *b {
                (*b, *at) = (xi, i);
            }
            let past = *b > 0.0 && xi < 0.5 * *b;
            if past || time >= *until {
                let peak = if past { refine(&x[q], *at, h) } else { *until };
                out[*k] = Some(0.25 / peak);
                (done[q], open) = (true, open - 1);
            }
        }
        open > 0
    });
    out
}

/// The static lean of every stem of `level` under the drag of a steady wind of `CALM` m/s
/// across it (as [`carriers`] moves it), with the levels below and the trunk held, m: the
/// mean over `window(stem)` seconds from rest of its end's displacement in the pose along
/// that wind, from its own clusters' turns ([`stem_chain`]). One entry per stem of the tree,
/// `None` for the other stems. Every cluster a stem carries holds the same wind, as the beam
/// takes its whole subtree's drag across it ([`crate::physics::beam::drag_bend`]); as
/// [`static_lean`], without the air's damping or reconfiguration, undamped.
fn side_stem_leans(tree: &Tree, hsm: &Hsm, level: u8, window: impl Fn(usize) -> f32) -> Vec<Option<f32>> {
    let (st, l) = (&tree.stems, &hsm.layout);
    let (mut out, rate) = (vec![None; st.len()], substep_rate(hsm));
    if rate <= 0.0 {
        return out;
    }
    let (carrier, push) = carriers(tree, level);
    let probes: Vec<(usize, Chain, f32)> = (0..st.len())
        .filter(|&k| push[k] != Vec3::ZERO)
        .map(|k| (k, stem_chain(tree, hsm, k), window(k).min(LONGEST)))
        .filter(|(_, chain, _)| !chain.is_empty())
        .collect();
    let mut state = hsm.state_at_rest();
    for (p, v) in state.velocity.iter_mut().enumerate() {
        if v[3] != FIXED && carrier[cluster_stem(tree, hsm, l.owner[p] as usize)] == NONE {
            v[3] = FIXED;
        }
    }
    // The wind each carried cluster holds (the step does not sample it).
    for (c, cs) in state.clusters.iter_mut().enumerate() {
        let k = carrier[cluster_stem(tree, hsm, c)];
        if k != NONE {
            let u = push[k as usize] * CALM;
            cs.wind = [u.x, u.y, u.z, 1.0];
        }
    }
    let h = 1.0 / rate;
    let mut step = hsm.step_params(0.0, h);
    (step.air, step.vogel_exponent, step.leaf_turbulence, step.sample_wind) = (0.0, 0.0, 0.0, 0);
    let longest = probes.iter().map(|p| p.2).fold(0.0f32, f32::max);
    let mut sum = vec![(0.0f64, 0usize); probes.len()];
    let mut open = probes.len();
    held_run(hsm, &mut state, step, (longest * rate).ceil() as usize, |state, _, _| {
        for (q, (k, chain, until)) in probes.iter().enumerate() {
            let (total, n) = &mut sum[q];
            if out[*k].is_some() || *n == usize::MAX {
                continue;
            }
            let xi = chain_end(chain, state).dot(push[*k]);
            if !xi.is_finite() {
                (*n, open) = (usize::MAX, open - 1);
                continue;
            }
            (*total, *n) = (*total + xi as f64, *n + 1);
            if (*n + 1) as f32 * h > *until {
                out[*k] = Some((*total / *n as f64) as f32);
                open -= 1;
            }
        }
        open > 0
    });
    out
}

/// Steps `state` from `step` (its `dt` the substep) without gravity or damping for at most
/// `steps` substeps, handing the state, the substep's index and the time at its end to
/// `read` after each substep until it answers that nothing is left to read.
fn held_run(
    hsm: &Hsm,
    state: &mut super::HsmState,
    mut step: super::RawHsmStep,
    steps: usize,
    mut read: impl FnMut(&super::HsmState, usize, f32) -> bool,
) {
    (step.gravity, step.damping) = ([0.0; 4], 1.0);
    for i in 0..steps {
        step.time = (i + 1) as f32 * step.dt;
        hsm.substep_with(&[], &[], state, step);
        if !read(state, i, step.time) {
            return;
        }
    }
}

/// The particles of stem `k`'s tip ring: its last segment cluster's tail ring.
fn tip_ring(tree: &Tree, hsm: &Hsm, k: usize) -> Option<Vec<usize>> {
    let count = tree.stems.segment_count[k];
    if count == 0 {
        return None;
    }
    let top = (tree.stems.first_segment[k] + count - 1) as usize;
    let c = hsm.layout.segment_cluster[top];
    if c == NONE {
        return None;
    }
    let info = hsm.layout.info[c as usize];
    let n = hsm.params.ring_size.min(info.slot_count) as usize;
    let end = (info.slot_offset + info.slot_count) as usize;
    Some(hsm.layout.slots[end - n..end].iter().map(|s| s.particle as usize).collect())
}

/// The time of the peak of `x` at step `at` (step `i` ends at `(i + 1) h`), refined on the
/// parabola through its neighbours.
fn refine(x: &[f32], at: usize, h: f32) -> f32 {
    let (a, b, c) = (x[at.saturating_sub(1)] as f64, x[at] as f64, x[at + 1] as f64);
    let curve = a - 2.0 * b + c;
    let shift = if at > 0 && curve < 0.0 { (0.5 * (a - c) / curve).clamp(-0.5, 0.5) } else { 0.0 };
    ((at as f64 + 1.0 + shift) * h as f64) as f32
}

/// Puts the trunk and every side stem at its first mode from the wood (see the module
/// docs): scales the layout's rates in place. Does nothing when the trunk gives no peak.
pub fn calibrate(tree: &Tree, hsm: &mut Hsm) {
    let target = hsm.layout.sway_hz * hsm.params.stiffness_scale.sqrt();
    let Some(f0) = trunk_pluck(tree, hsm, FIRST / target) else {
        return;
    };
    // Plucked as built, every frequency is `ratio` times what it will be once scaled.
    let ratio = f0 / target;
    let modes = crate::physics::stem_frequencies(tree, hsm.params.min_radius);
    let pace = hsm.params.stiffness_scale.sqrt() * ratio;
    let want = |k: usize| modes.hz(k) * pace;
    let deepest = tree.stems.level.iter().copied().max().unwrap_or(0);
    // The trunk's own level holds the stems its forks grow, if it forks.
    let st = &tree.stems;
    let forks = (0..st.len()).any(|k| k != TRUNK && st.level[k] == 0 && st.segment_count[k] > 0);
    let lowest = if forks { 0 } else { 1 };
    for level in (lowest..=deepest).rev() {
        let measured = side_stem_frequencies(tree, hsm, level, |k| 1.0 / want(k).max(1e-3));
        let factors: Vec<f32> = measured
            .iter()
            .enumerate()
            .map(|(k, f)| match f {
                Some(f) if *f > 0.0 => (want(k) / f).powi(2).clamp(STEM_FACTOR.0, STEM_FACTOR.1),
                _ => 1.0,
            })
            .collect();
        hsm.layout.scale_stem_rates(tree, &factors);
    }
    // Stiffer side stems load the trunk more: it is brought back to where it was, and again
    // while it is still off and each pass at least halves what is left (a trunk that the
    // hold keeps from its rates, or that hands its swing to the crown, does not follow them).
    if deepest > 0 || forks {
        trunk_back(tree, hsm, f0, TRUNK_PASSES);
    }
    // Each stem's static bend under its drag and all it carries, the beam's, m.
    let p = &hsm.params;
    let areas = crate::physics::beam::drag_areas(tree, p.drag, p.leaf_drag, hsm.layout.shelter);
    let pressure = 0.5 * crate::physics::AIR_DENSITY * CALM * CALM;
    let stiffness = p.stiffness_scale.max(f32::MIN_POSITIVE);
    let bends: Vec<f32> = crate::physics::beam::drag_bend(tree, p.min_radius, &areas)
        .tip
        .iter()
        .map(|tip| tip * pressure / stiffness)
        .collect();
    // A lean as built, once the rates are scaled and without the drag's own scale.
    let calibrated = (f0 / target).powi(2) / hsm.params.drag_scale.max(f32::MIN_POSITIVE);
    let mut shape = trunk_drag(tree, hsm, f0, calibrated, bends[TRUNK]);
    // 5. The leaders a forked trunk grows: under the loads that lean the trunk as its beam,
    // each stiffened until it leans as its own (see the module docs), then the trunk's
    // frequency and drag once more.
    if forks {
        let windows: Vec<f32> = (0..tree.stems.len()).map(|k| LEAN_PERIODS / want(k).max(1e-3)).collect();
        let leans = side_stem_leans(tree, hsm, 0, |k| windows[k]);
        let factors: Vec<f32> = leans
            .iter()
            .zip(&bends)
            .map(|(lean, &beam)| match lean.map(|x| x * calibrated) {
                Some(x) if x > 0.0 && beam > 0.0 && (x * beam).is_finite() => {
                    (x / beam).clamp(STEM_FACTOR.0, STEM_FACTOR.1)
                }
                _ => 1.0,
            })
            .collect();
        hsm.layout.scale_stem_rates(tree, &factors);
        trunk_back(tree, hsm, f0, 1);
        shape = trunk_drag(tree, hsm, f0, calibrated, bends[TRUNK]).or(shape);
    }
    hsm.layout.scale_rates((target / f0).powi(2).clamp(1e-4, 1e4));
    // 6. The air's damping, weighed as the calibrated trunk's mode moves its inertia.
    if let Some(shape) = shape {
        hsm.layout.air_scale = air_scale(hsm, &shape);
    }
}

/// Brings the trunk's pluck back to `f0` by scaling its rates, in at most `passes` passes: a
/// further pass only while it is off by more than [`TRUNK_TOLERANCE`] and the last pass at
/// least halved what was left.
fn trunk_back(tree: &Tree, hsm: &mut Hsm, f0: f32, passes: usize) {
    let mut factors = vec![1.0; tree.stems.len()];
    let mut off = f32::INFINITY;
    for pass in 0..passes {
        let Some(f1) = trunk_pluck(tree, hsm, AGAIN / f0) else {
            break;
        };
        let now = (f1 / f0 - 1.0).abs();
        if pass > 0 && (now <= TRUNK_TOLERANCE || now > 0.5 * off) {
            break;
        }
        off = now;
        factors[TRUNK] = (f0 / f1).powi(2).clamp(STEM_FACTOR.0, STEM_FACTOR.1);
        hsm.layout.scale_stem_rates(tree, &factors);
    }
}

/// Scales every particle's drag so the trunk top's static lean in a steady wind, as built
/// and read as `calibrated` times the run's, is `beam` (m, the beam's under the same drag).
/// The lean's shape, each particle's mean x displacement (see [`static_lean`]), for step 6.
fn trunk_drag(tree: &Tree, hsm: &mut Hsm, f0: f32, calibrated: f32, beam: f32) -> Option<Vec<f32>> {
    let (mean, shape) = static_lean(tree, hsm, LEAN_PERIODS / f0, CALM)?;
    let lean = mean * calibrated;
    if lean > 0.0 && beam > 0.0 && (lean * beam).is_finite() {
        hsm.layout.scale_loads((beam / lean).clamp(LOAD_FACTOR.0, LOAD_FACTOR.1));
    }
    Some(shape)
}

/// Step 6: the factor on the air's damping that gives the trunk's mode, in the shape
/// `shape` (each particle's displacement), the air's damping ratio it has with the
/// particles' own masses ([`super::HsmLayout::air_scale`]). The drag's damping is each
/// particle's `m k_d`; where the hold keeps a particle (`Σ w > hold`, the weights of the
/// layout as it stands at its own substep) it moves as if its mass were `μ = m Σ w / hold`,
/// so the mode's damping ratio is `Σ μ k_d φ² / (2 ω Σ μ φ²)` where the tree's is
/// `Σ m k_d φ² / (2 ω Σ m φ²)`. Particles that move with the tree but do not push back on it
/// (leaf blades without [`super::HsmParams::leaf_reaction`]) and fixed ones are left out. 1
/// where either sum vanishes.
fn air_scale(hsm: &Hsm, shape: &[f32]) -> f32 {
    let l = &hsm.layout;
    let h = 1.0 / substep_rate(hsm);
    let hold = hsm.hold(h);
    let (mut inertia, mut held_inertia, mut damping, mut held_damping) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for (i, &phi) in shape.iter().enumerate() {
        if l.free[i] == 0.0 || (l.info[l.owner[i] as usize].kind == kind::LEAF && !hsm.params.leaf_reaction) {
            continue;
        }
        let weight: f32 = l.member[l.member_offset[i] as usize..l.member_offset[i + 1] as usize]
            .iter()
            .map(|m| super::kernels::cluster_weight(&l.clusters[m.cluster as usize], h, hold))
            .sum();
        let held = (weight / hold).max(1.0) as f64;
        let (m, phi2) = (l.mass[i] as f64, phi as f64 * phi as f64);
        let c = m * l.rest[i][3].max(0.0) as f64;
        inertia += m * phi2;
        held_inertia += held * m * phi2;
        damping += c * phi2;
        held_damping += held * c * phi2;
    }
    let scale = (held_inertia / inertia) / (held_damping / damping);
    if scale.is_finite() && scale > 0.0 { (scale as f32).clamp(LOAD_FACTOR.0, LOAD_FACTOR.1) } else { 1.0 }
}

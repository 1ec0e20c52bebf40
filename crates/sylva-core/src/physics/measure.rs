//! Reading a tree's motion the way field studies do: sway frequency from zero crossings,
//! damping ratio from the logarithmic decrement of successive peaks, least-squares lines
//! (frequency against DBH/H²), and how much of a branch's own motion is fast (flutter).

use crate::Tree;
use crate::model::NONE;
use crate::pose::Pose;
use glam::{Quat, Vec3};
use rustfft::{FftPlanner, num_complex::Complex};

/// Frequency of an oscillating series sampled every `dt` s, Hz: upward crossings of its mean
/// over the span between the first and the last. `None` with fewer than three crossings.
pub fn sway_frequency(series: &[f32], dt: f32) -> Option<f32> {
    let mean = series.iter().map(|&x| x as f64).sum::<f64>() / series.len().max(1) as f64;
    let mut crossings = Vec::new();
    for k in 1..series.len() {
        let (a, b) = (series[k - 1] as f64 - mean, series[k] as f64 - mean);
        if a < 0.0 && b >= 0.0 {
            crossings.push((k - 1) as f64 + a / (a - b));
        }
    }
    if crossings.len() < 3 {
        return None;
    }
    let span = crossings[crossings.len() - 1] - crossings[0];
    Some(((crossings.len() - 1) as f64 / (span * dt as f64)) as f32)
}

/// Frequency of an oscillation ringing down about `centre`, Hz: crossings of `centre` (both
/// ways, half a period apart) while the motion is still above `floor` (a heavily damped
/// ring-down soon sinks into rounding, where crossings of a mean carry no period). `None`
/// with fewer than three crossings.
pub fn ringdown_frequency(series: &[f32], dt: f32, centre: f32, floor: f32) -> Option<f32> {
    let end = series.iter().rposition(|&x| (x - centre).abs() > floor)? + 1;
    let live = &series[..(end + 1).min(series.len())];
    let mut crossings = Vec::new();
    for k in 1..live.len() {
        let (a, b) = (live[k - 1] as f64 - centre as f64, live[k] as f64 - centre as f64);
        if (a < 0.0) != (b < 0.0) {
            crossings.push((k - 1) as f64 + a / (a - b));
        }
    }
    if crossings.len() < 3 {
        return None;
    }
    let span = crossings[crossings.len() - 1] - crossings[0];
    Some(((crossings.len() - 1) as f64 / (2.0 * span * dt as f64)) as f32)
}

/// Damping ratio of a decaying oscillation about `centre`, from the logarithmic decrement
/// of successive peaks of |x − centre| (a half-period apart): the slope of ln(peak) against
/// the peak's number, fitted over every peak above `floor`, is −δ/2, and
/// `ζ = δ / √(4π² + δ²)`. `None` with fewer than three peaks, or when the peaks do not decay
/// as one exponential (fit R² under 0.7: motion that is driven, not ringing down).
pub fn damping_ratio(series: &[f32], centre: f32, floor: f32) -> Option<f32> {
    let mut peaks = Vec::new();
    for k in 1..series.len().saturating_sub(1) {
        let (a, b, c) = ((series[k - 1] - centre).abs(), (series[k] - centre).abs(), (series[k + 1] - centre).abs());
        if b > a && b >= c && b > floor {
            peaks.push((peaks.len() as f64, (b as f64).ln()));
        }
    }
    if peaks.len() < 3 {
        return None;
    }
    let (slope, _, r2) = linear_fit(&peaks);
    if slope >= 0.0 || r2 < 0.7 {
        return None;
    }
    let delta = -2.0 * slope;
    Some((delta / (4.0 * std::f64::consts::PI * std::f64::consts::PI + delta * delta).sqrt()) as f32)
}

/// Least-squares line through `(x, y)`: (slope, intercept, R²).
pub fn linear_fit(points: &[(f64, f64)]) -> (f64, f64, f64) {
    let n = points.len() as f64;
    let (sx, sy) = (points.iter().map(|p| p.0).sum::<f64>(), points.iter().map(|p| p.1).sum::<f64>());
    let (mx, my) = (sx / n, sy / n);
    let sxx: f64 = points.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let syy: f64 = points.iter().map(|p| (p.1 - my) * (p.1 - my)).sum();
    let slope = sxy / sxx;
    let r2 = if syy > 0.0 { sxy * sxy / (sxx * syy) } else { 1.0 };
    (slope, my - slope * mx, r2)
}

/// Where stem `stem`'s tip lies relative to its attachment, m: the offset from the stem's base
/// to its tip, in the frame of the segment it grows from (turned back by that segment's turn
/// from rest), so the parent's own sway is taken out and what remains is the stem's own
/// motion. The trunk's offset is in the world frame.
pub fn tip_from_attachment(tree: &Tree, pose: &Pose, stem: usize) -> Vec3 {
    let s = &tree.stems;
    let base = s.first_segment[stem] as usize;
    let tip = base + s.segment_count[stem].max(1) as usize - 1;
    let parent = tree.segments.parent[base];
    let turn = if parent == NONE {
        Quat::IDENTITY
    } else {
        pose.orientation[parent as usize] * tree.segments.orientation[parent as usize].inverse()
    };
    turn.inverse() * (pose.end(tree, tip) - pose.start[base])
}

/// A series' variance above `f` Hz and in all (its mean removed; periodogram of the whole
/// series sampled every `dt` s), in the series' units squared times its length.
pub fn variance_above(series: &[f32], dt: f32, f: f32) -> (f32, f32) {
    let n = series.len();
    let mean = series.iter().sum::<f32>() / n.max(1) as f32;
    let mut buf: Vec<Complex<f32>> = series.iter().map(|&x| Complex::new(x - mean, 0.0)).collect();
    FftPlanner::new().plan_fft_forward(n).process(&mut buf);
    let df = 1.0 / (n as f32 * dt);
    let (mut hi, mut all) = (0.0, 0.0);
    for (k, c) in buf.iter().enumerate().take(n / 2).skip(1) {
        all += c.norm_sqr();
        if k as f32 * df > f {
            hi += c.norm_sqr();
        }
    }
    (hi, all)
}

/// Where a series' energy is: the frequency of the largest bin of its premultiplied
/// periodogram `f S(f)`, Hz (its mean removed; sampled every `dt` s). The premultiplied form
/// shows energy per logarithmic band, as wind and canopy spectra are read (Kaimal et al.
/// 1972): a red spectrum's low end does not hide a resonance above it. `None` for a constant
/// series.
pub fn spectral_peak(series: &[f32], dt: f32) -> Option<f32> {
    let n = series.len();
    let mean = series.iter().sum::<f32>() / n.max(1) as f32;
    let mut buf: Vec<Complex<f32>> = series.iter().map(|&x| Complex::new(x - mean, 0.0)).collect();
    FftPlanner::new().plan_fft_forward(n).process(&mut buf);
    let df = 1.0 / (n as f32 * dt);
    let (k, power) = buf
        .iter()
        .enumerate()
        .take(n / 2)
        .skip(1)
        .map(|(k, c)| (k, k as f32 * c.norm_sqr()))
        .fold((0, 0.0f32), |best, (k, p)| if p > best.1 { (k, p) } else { best });
    (power > 0.0).then_some(k as f32 * df)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A damped sine of known frequency and damping ratio reads back as both; a sum of
    /// incommensurate sines (driven motion) has no damping ratio.
    #[test]
    fn a_damped_sine_reads_back_its_frequency_and_damping() {
        let (f, zeta, dt) = (0.7f32, 0.05f32, 1.0 / 120.0);
        let w = std::f32::consts::TAU * f;
        let wd = w * (1.0 - zeta * zeta).sqrt();
        let x: Vec<f32> = (0..6000).map(|k| k as f32 * dt).map(|t| (-zeta * w * t).exp() * (wd * t).cos()).collect();
        let fm = sway_frequency(&x, dt).unwrap();
        assert!((fm / (wd / std::f32::consts::TAU) - 1.0).abs() < 0.01, "{fm}");
        // A heavily damped ring-down: its mean sits off zero, so the crossings of the rest
        // position tell its period.
        let wh = w * (1.0f32 - 0.25 * 0.25).sqrt();
        let heavy: Vec<f32> =
            (0..6000).map(|k| k as f32 * dt).map(|t| (-0.25 * w * t).exp() * (wh * t).cos()).collect();
        let fr = ringdown_frequency(&heavy, dt, 0.0, 0.01).unwrap();
        assert!((fr / (wh / std::f32::consts::TAU) - 1.0).abs() < 0.005, "{fr}");
        // The mean's crossings read it several per cent low.
        let fm = sway_frequency(&heavy, dt).map_or(0.0, |f| f / (wh / std::f32::consts::TAU));
        assert!((fm - 1.0).abs() > 0.02, "{fm}");
        let z = damping_ratio(&x, 0.0, 0.01).unwrap();
        assert!((z / zeta - 1.0).abs() < 0.05, "{z}");
        let driven: Vec<f32> =
            (0..6000).map(|k| k as f32 * dt).map(|t| t.sin() + (2.7 * t).sin() + (5.1 * t).cos()).collect();
        assert_eq!(damping_ratio(&driven, 0.0, 0.01), None);
        let (slope, icpt, r2) = linear_fit(&[(0.0, 1.0), (1.0, 3.0), (2.0, 5.0)]);
        assert!((slope - 2.0).abs() < 1e-12 && (icpt - 1.0).abs() < 1e-12 && (r2 - 1.0).abs() < 1e-12);
    }

    /// Two sines, of 0.5 and 3 Hz with variances 1 and ¼: a fifth of the variance lies above
    /// 1.5 Hz.
    #[test]
    fn variance_above_splits_two_sines_by_their_power() {
        let dt = 1.0 / 60.0;
        let x: Vec<f32> = (0..3600)
            .map(|k| k as f32 * dt)
            .map(|t| {
                2f32.sqrt() * (std::f32::consts::TAU * 0.5 * t).sin()
                    + 0.5 * 2f32.sqrt() * (std::f32::consts::TAU * 3.0 * t).cos()
            })
            .collect();
        let (hi, all) = variance_above(&x, dt, 1.5);
        assert!((hi / all - 0.2).abs() < 1e-3, "{}", hi / all);
        let (none, _) = variance_above(&x, dt, 4.0);
        assert!(none / all < 1e-6);
    }

    /// A branch carried by its parent's turn stays put in the parent's frame; bending the
    /// branch itself moves its tip there.
    #[test]
    fn a_tip_turned_with_its_parent_stays_put_in_the_parent_s_frame() {
        let tree = crate::species::SpeciesSource::resolve("quaking_aspen")
            .unwrap()
            .generate(1, &Default::default(), None)
            .unwrap();
        let stem = (0..tree.stems.len()).find(|&k| tree.stems.parent[k] != NONE).unwrap();
        let rest = Pose::rest(&tree);
        let at_rest = tip_from_attachment(&tree, &rest, stem);
        // Turn the whole tree 0.3 rad about its root.
        let q = Quat::from_rotation_z(0.3);
        let mut turned = rest.clone();
        for i in 0..tree.segments.len() {
            turned.start[i] = q * rest.start[i];
            turned.orientation[i] = q * rest.orientation[i];
        }
        let carried = tip_from_attachment(&tree, &turned, stem);
        assert!((carried - at_rest).length() < 1e-4 * at_rest.length(), "{carried} against {at_rest}");
        // The trunk's offset is in the world frame, so it turns.
        assert!((tip_from_attachment(&tree, &turned, 0) - q * tip_from_attachment(&tree, &rest, 0)).length() < 1e-3);
        // Turn only the branch's segments about its base.
        let base = tree.stems.first_segment[stem] as usize;
        let pivot = rest.start[base];
        let mut bent = rest.clone();
        for i in base..base + tree.stems.segment_count[stem] as usize {
            bent.start[i] = pivot + q * (rest.start[i] - pivot);
            bent.orientation[i] = q * rest.orientation[i];
        }
        let moved = tip_from_attachment(&tree, &bent, stem);
        assert!((moved - at_rest).length() > 0.1 * at_rest.length(), "{moved} against {at_rest}");
    }
}

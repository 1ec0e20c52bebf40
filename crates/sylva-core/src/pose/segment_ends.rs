//! CPU twin of `segment_ends.wgsl`.

use crate::model::RawSegment;
use glam::{Quat, Vec3};
use rayon::prelude::*;

/// `ends[i] = start[i] + orientation[i] · (0, length[i], 0)`, w = 1.
/// Bindings as in the kernel: 0 = segments (read), 1 = ends (write).
pub fn segment_ends(segments: &[RawSegment], ends: &mut [[f32; 4]]) {
    ends.par_iter_mut().zip(segments.par_iter()).for_each(|(end, s)| {
        let q = Quat::from_array(s.orientation);
        let e = Vec3::from_array(s.start) + q * Vec3::new(0.0, s.length, 0.0);
        *end = [e.x, e.y, e.z, 1.0];
    });
}

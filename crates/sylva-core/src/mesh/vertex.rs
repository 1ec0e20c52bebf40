//! The vertex every mesh kernel writes each frame and the renderer draws as it is: 16 bytes.
//!
//! - **Position**, three f32: world space over a 40 m tree needs millimetres at the top.
//! - **Normal**, octahedral in two snorm16 (Cigolle et al. 2014, "A Survey of Efficient
//!   Representations for Independent Unit Vectors", JCGT 3(2)): the unit sphere folded onto
//!   the square, under 1e-4 rad of error (tested); the renderer reads it as `Snorm16x2`.
//!
//! Texture coordinates do not move with the pose, so they are not written per frame: they
//! are a second, static stream of [`Uv`] made once per layout ([`crate::mesh::MeshLayout::tube_uv`],
//! `leaf_uv`, [`crate::mesh::DeformLayout::uv`]), which the renderer binds beside the
//! vertices. They stay f32: bark `v` runs to ~100 along a thin stem (rest arc length over the
//! base circumference), where f16 would step by 1/16 of the texture.
//!
//! The WGSL twins are `Vertex`, `oct_encode` and `oct_decode` in `mesh/vertex.wgsl`.

use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3};

/// Texture coordinates (u, v) of a vertex, in the static stream beside [`RawVertex`].
pub type Uv = [f32; 2];

/// One output vertex, 16 bytes. WGSL: `struct Vertex` in `vertex.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawVertex {
    /// Position, m.
    pub position: [f32; 3],
    /// Unit normal, octahedral: x in the low 16 bits, y in the high, each snorm16
    /// ([`oct_encode`]; [`RawVertex::normal`] decodes it).
    pub normal_oct: u32,
}

impl RawVertex {
    /// A vertex at `position` with unit `normal`.
    #[inline]
    pub fn new(position: Vec3, normal: Vec3) -> Self {
        Self { position: position.to_array(), normal_oct: oct_encode(normal) }
    }

    /// The position.
    #[inline]
    pub fn pos(&self) -> Vec3 {
        Vec3::from_array(self.position)
    }

    /// The unit normal (decoded).
    #[inline]
    pub fn normal(&self) -> Vec3 {
        oct_decode(self.normal_oct)
    }
}

/// ±1 by sign, +1 at zero.
#[inline]
fn sign_not_zero(p: Vec2) -> Vec2 {
    Vec2::new(if p.x >= 0.0 { 1.0 } else { -1.0 }, if p.y >= 0.0 { 1.0 } else { -1.0 })
}

/// WGSL's `pack2x16snorm` rule for one component: ⌊0.5 + 32767 · clamp(x, −1, 1)⌋. The
/// floor is the truncation, less one where that rounded a negative value up: exact in this
/// range, and inline, where `f32::floor` is a libm call on x86-64's baseline (no `roundps`).
#[inline]
fn snorm16(x: f32) -> u32 {
    let y = 0.5 + 32767.0 * x.clamp(-1.0, 1.0);
    let t = y as i32;
    (t - i32::from(t as f32 > y)) as u32 & 0xffff
}

/// `max(c / 32767, −1)`, as a `Snorm16` vertex attribute reads it.
#[inline]
fn unsnorm16(bits: u32) -> f32 {
    (bits as u16 as i16 as f32 / 32767.0).max(-1.0)
}

/// A unit vector folded onto the octahedron's square, two snorm16 packed in a u32 (a zero
/// vector gives +z).
#[inline]
pub fn oct_encode(n: Vec3) -> u32 {
    let p = Vec2::new(n.x, n.y) / (n.x.abs() + n.y.abs() + n.z.abs()).max(1e-30);
    let q = if n.z < 0.0 { (Vec2::ONE - Vec2::new(p.y.abs(), p.x.abs())) * sign_not_zero(p) } else { p };
    snorm16(q.x) | (snorm16(q.y) << 16)
}

/// The unit vector of [`oct_encode`]'s bits.
#[inline]
pub fn oct_decode(bits: u32) -> Vec3 {
    let p = Vec2::new(unsnorm16(bits & 0xffff), unsnorm16(bits >> 16));
    let z = 1.0 - p.x.abs() - p.y.abs();
    let q = if z < 0.0 { (Vec2::ONE - Vec2::new(p.y.abs(), p.x.abs())) * sign_not_zero(p) } else { p };
    Vec3::new(q.x, q.y, z).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn octahedral_normals_round_trip_within_1e_4_rad() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let mut worst = 0.0f32;
        let axes = [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z];
        let random = (0..200_000)
            .map(|_| Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)));
        for n in axes.into_iter().chain(random) {
            let n = n.normalize_or(Vec3::Z);
            let back = oct_decode(oct_encode(n));
            // The chord, as the angle's f32 acos near 1 is coarser than the error.
            worst = worst.max((n - back).length());
        }
        assert!(worst < 1e-4, "largest octahedral error {worst} rad");
        assert_eq!(oct_decode(oct_encode(Vec3::ZERO)), Vec3::Z);
    }

    #[test]
    fn snorm16_floors_as_f32_floor() {
        let floor = |x: f32| ((0.5 + 32767.0 * x.clamp(-1.0, 1.0)).floor() as i32 as u32) & 0xffff;
        let mut rng = rand::rngs::StdRng::seed_from_u64(11);
        // Every value whose scaled form is a whole or half step, their neighbours one ulp
        // either side, the ends, the signed zeros and NaN.
        let steps = (-65536..=65536).map(|k| k as f32 / 65534.0);
        let edges = steps.flat_map(|x| [x, f32::from_bits(x.to_bits() + 1), f32::from_bits(x.to_bits().max(1) - 1)]);
        let special = [0.0, -0.0, 1.0, -1.0, 1.5, -1.5, f32::MIN_POSITIVE, -f32::MIN_POSITIVE, f32::NAN];
        let random = (0..200_000).map(|_| rng.random_range(-1.2f32..1.2));
        for x in edges.chain(special).chain(random) {
            assert_eq!(snorm16(x), floor(x), "{x} ({:#x})", x.to_bits());
        }
    }

    #[test]
    fn a_vertex_is_16_bytes() {
        assert_eq!(std::mem::size_of::<RawVertex>(), 16);
    }
}

//! Skjermo's branch deformer (§3): every stem is a parametric grid (v along the stem, θ
//! around it) bent along its animated cubic Bézier.
//!
//! 1. **Grid → cylinder → unbent branch** (eqs. 1–6): the radius at (v, θ) is
//!    `f_taper · f_flare · f_bulges · f_lobes` with `f_taper = r (1 − v^t)` (eq. 2; never
//!    below [`super::MIN_RADIUS_FRACTION`] of r, so the tip stays a ring), `f_flare = f/100 ·
//!    100^(1−8v) + 1` (eq. 3), `f_bulges = 1 + b_d sin(2π b_n v)` (eq. 4), `f_lobes = 1 + l_d
//!    sin(l_n θ)(1 − v l_t)` (eq. 5); `(f_u, f_v, f_w) = (v, sin θ R, cos θ R)` (eq. 6).
//! 2. **Generalised de Casteljau along the Bézier** (eqs. 7, 9; Chang & Rockwood): handles
//!    from Sloan's moving frame (eq. 8, Bloomenthal): `L_i = normalize(P_{i+1} − P_i)`,
//!    `S₀ = L₀ × O, T₀ = S₀ × L₀, T₁ = S₀ × L₁, S₁ = L₁ × T₁, T₂ = S₁ × L₂, S₂ = L₂ × T₂` (all
//!    normalised), with O the parent's tangent at the branching point (world X for a
//!    trunk); then `R⁰ᵢ = lerp(Pᵢ, Pᵢ₊₁, u) + Sᵢ f_v + Tᵢ f_w` and two more lerps.
//! 3. **Normals through the Jacobian** (eq. 10): the derivatives of eq. 6 in θ and v are
//!    carried through eq. 9 analytically (the Jacobian–vector products), `n = ∂P/∂θ × ∂P/∂u`.
//!
//! Each frame reads the stems' control points as Skjermo's method keeps them (rest plus
//! per-step displacement, [`crate::methods::skjermo`]). The CPU reference
//! `mesh::skjermo_deform` is the twin of `skjermo_deform.wgsl` (one ring per work item).

use super::{MIN_RADIUS_FRACTION, MeshError, RawMeshInfo};
use crate::model::Tree;
use bytemuck::{Pod, Zeroable};

/// Per-stem shape of the unbent branch, 48 bytes. WGSL: `struct DeformShape`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawDeformShape {
    /// Base radius r, m.
    pub radius: f32,
    /// Taper exponent t (eq. 2).
    pub taper: f32,
    /// Flare f (eq. 3).
    pub flare: f32,
    /// Bulges b_n (eq. 4).
    pub bulges: f32,
    /// Bulge depth b_d.
    pub bulge_depth: f32,
    /// Lobes l_n (eq. 5).
    pub lobes: f32,
    /// Lobe depth l_d.
    pub lobe_depth: f32,
    /// Lobe fade l_t.
    pub lobe_fade: f32,
    /// Where the taper reaches its floor, `(1 − MIN_RADIUS_FRACTION)^(1/t)`: from here on
    /// the radius is held (computed once, so the CPU and GPU switch at the same ring).
    pub v_floor: f32,
    /// Padding.
    pub _pad: [f32; 3],
}

/// One cross-section of the grid, 16 bytes. WGSL: `struct DeformRing`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct RawDeformRing {
    /// Stem.
    pub stem: u32,
    /// Position along the stem, 0…1 (the Bézier parameter u = v).
    pub v: f32,
    /// Bark texture coordinate along the stem.
    pub tex_v: f32,
    /// Padding.
    pub _pad: u32,
}

/// Deformer parameters. The trunk's shape comes from the species ([`Self::for_tree`]:
/// Weber–Penn `Flare`, `Lobes`, `LobeDepth`, and the species' bulges); the defaults give a
/// round, unflared trunk.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeformerParams {
    /// Sides around each stem. Default 8, as the tubes.
    pub sides: u32,
    /// Cross-sections per stem segment (the grid's rows follow the stem's resolution).
    /// Default 2: one Bézier per stem needs fewer rows than the Hermite chain.
    pub rows_per_segment: u32,
    /// Flare of trunks (eq. 3), applied to the unflared base radius. Default 0; the species'
    /// `flare` with [`Self::for_tree`]. Branches: 0.
    pub trunk_flare: f32,
    /// Lobes of trunks (eq. 5). Default 0; the species' `lobes`. Branches: none.
    pub trunk_lobes: f32,
    /// Lobe depth of trunks, 0 to 0.9. Default 0; the species' `lobe_depth`.
    pub trunk_lobe_depth: f32,
    /// Lobe fade (eq. 5, `l_t`). Default 1: lobes vanish toward the tip, as Skjermo's roots
    /// spread at the base (Weber–Penn keeps them all the way up).
    pub lobe_fade: f32,
    /// Bulges per stem (eq. 4). Default 0; the species' `bulges`.
    pub bulges: f32,
    /// Bulge depth, 0 to 0.9. Default 0; the species' `bulge_depth`.
    pub bulge_depth: f32,
}

impl Default for DeformerParams {
    fn default() -> Self {
        Self {
            sides: 8,
            rows_per_segment: 2,
            trunk_flare: 0.0,
            trunk_lobes: 0.0,
            trunk_lobe_depth: 0.0,
            lobe_fade: 1.0,
            bulges: 0.0,
            bulge_depth: 0.0,
        }
    }
}

impl DeformerParams {
    /// The defaults with the trunk's shape from `tree`'s species ([`crate::model::TrunkShape`]).
    pub fn for_tree(tree: &Tree) -> Self {
        let t = &tree.trunk_shape;
        Self {
            trunk_flare: t.flare,
            trunk_lobes: t.lobes as f32,
            trunk_lobe_depth: t.lobe_depth,
            bulges: t.bulges,
            bulge_depth: t.bulge_depth,
            ..Self::default()
        }
    }
}

/// The fixed grid of every stem.
#[derive(Debug, Clone, PartialEq)]
pub struct DeformLayout {
    /// Parameters.
    pub params: DeformerParams,
    /// Rings (per stem, base to tip).
    pub rings: Vec<RawDeformRing>,
    /// Per-stem shapes.
    pub shapes: Vec<RawDeformShape>,
    /// Triangle indices.
    pub indices: Vec<u32>,
}

impl DeformLayout {
    /// The grid for every stem of `tree`; the taper exponent of each stem is fitted to its
    /// segments' radii at mid-length (`1 − 0.5^t = r(½)/r`).
    pub fn new(tree: &Tree, params: DeformerParams) -> Result<Self, MeshError> {
        let bad = |field, value: String, expected| Err(MeshError::Param { field, value, expected });
        if !(3..=super::MAX_SIDES).contains(&params.sides) {
            return bad("sides", params.sides.to_string(), "3 to 64");
        }
        if !(1..=super::MAX_SAMPLES).contains(&params.rows_per_segment) {
            return bad("rows_per_segment", params.rows_per_segment.to_string(), "1 to 32");
        }
        for (field, v) in [("trunk_lobe_depth", params.trunk_lobe_depth), ("bulge_depth", params.bulge_depth)] {
            if !(v.is_finite() && (0.0..0.9).contains(&v)) {
                return bad(field, v.to_string(), "0 to 0.9");
            }
        }
        let s = &tree.segments;
        let st = &tree.stems;
        let stride = params.sides + 1;
        let rows_total: u64 = st.segment_count.iter().map(|&n| n as u64 * params.rows_per_segment as u64 + 1).sum();
        if rows_total * stride as u64 > super::MAX_VERTICES {
            return Err(MeshError::TooLarge { vertices: rows_total * stride as u64, limit: super::MAX_VERTICES });
        }
        let (mut rings, mut shapes, mut indices) = (Vec::new(), Vec::new(), Vec::new());
        for k in 0..st.len() {
            let first = st.first_segment[k] as usize;
            let n = st.segment_count[k] as usize;
            let trunk = st.level[k] == 0;
            // A trunk's segment radii already carry the species' flare: eq. 3 flares the
            // unflared radius, so that flare is applied once.
            let unflare = if trunk { tree.trunk_shape.flare_factor(0.0) } else { 1.0 };
            let r = (s.radius_base[first] / unflare).max(1e-5);
            // Radius at mid-length along the chain.
            let half = 0.5 * st.length[k];
            let (mut acc, mut mid) = (0.0f32, s.radius_tip[first + n - 1]);
            for i in first..first + n {
                if acc + s.length[i] >= half {
                    let f = ((half - acc) / s.length[i].max(1e-9)).clamp(0.0, 1.0);
                    mid = s.radius_base[i] + (s.radius_tip[i] - s.radius_base[i]) * f;
                    break;
                }
                acc += s.length[i];
            }
            let m = (1.0 - mid / r).clamp(0.05, 0.95);
            let taper = (m.ln() / 0.5f32.ln()).clamp(0.2, 10.0);
            shapes.push(RawDeformShape {
                radius: r,
                taper,
                flare: if trunk { params.trunk_flare } else { 0.0 },
                bulges: params.bulges,
                bulge_depth: params.bulge_depth,
                lobes: if trunk { params.trunk_lobes } else { 0.0 },
                lobe_depth: if trunk { params.trunk_lobe_depth } else { 0.0 },
                lobe_fade: params.lobe_fade,
                v_floor: (1.0 - MIN_RADIUS_FRACTION).powf(1.0 / taper),
                _pad: [0.0; 3],
            });
            let rows = n as u32 * params.rows_per_segment;
            let first_ring = rings.len() as u32;
            let tex = st.length[k] / (std::f32::consts::TAU * r);
            for j in 0..=rows {
                let v = j as f32 / rows as f32;
                rings.push(RawDeformRing { stem: k as u32, v, tex_v: v * tex, _pad: 0 });
            }
            for j in 0..rows {
                for c in 0..params.sides {
                    let a = (first_ring + j) * stride + c;
                    let (b, cc) = (a + 1, a + stride);
                    let d = cc + 1;
                    indices.extend_from_slice(&[a, b, d, a, d, cc]);
                }
            }
        }
        Ok(Self { params, rings, shapes, indices })
    }

    /// Kernel constants (`rings` and `sides` are what the kernel reads).
    pub fn info(&self) -> RawMeshInfo {
        RawMeshInfo {
            sides: self.params.sides,
            rings: self.rings.len() as u32,
            leaf_sides: 0,
            leaves: 0,
            details: 0,
            _pad: [0; 3],
        }
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.rings.len() * (self.params.sides as usize + 1)
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Texture coordinates, one per vertex (the static stream beside the deformed vertices):
    /// `u` around the ring (the seam column at 1), `v` the ring's [`RawDeformRing::tex_v`].
    pub fn uv(&self) -> Vec<super::Uv> {
        let sides = self.params.sides;
        self.rings.iter().flat_map(|r| (0..=sides).map(move |c| [c as f32 / sides as f32, r.tex_v])).collect()
    }
}

/// The unbent branch's radius and its derivatives in v and θ at (v, θ) (eqs. 2–5).
pub fn deform_radius(s: &RawDeformShape, v: f32, theta: f32) -> (f32, f32, f32) {
    let (taper, taper_d) = if v >= s.v_floor {
        (MIN_RADIUS_FRACTION * s.radius, 0.0)
    } else {
        let vt = if v > 0.0 { v.powf(s.taper) } else { 0.0 };
        (s.radius * (1.0 - vt), -s.radius * s.taper * v.max(1e-4).powf(s.taper - 1.0))
    };
    let ln100 = std::f32::consts::LN_10 * 2.0;
    let e = (ln100 * (1.0 - 8.0 * v)).exp();
    let flare = s.flare / 100.0 * e + 1.0;
    let flare_d = s.flare / 100.0 * e * (-8.0 * ln100);
    let w = std::f32::consts::TAU * s.bulges;
    let bulge = 1.0 + s.bulge_depth * (w * v).sin();
    let bulge_d = s.bulge_depth * w * (w * v).cos();
    let fade = 1.0 - v * s.lobe_fade;
    let lobe = 1.0 + s.lobe_depth * (s.lobes * theta).sin() * fade;
    let lobe_v = -s.lobe_depth * (s.lobes * theta).sin() * s.lobe_fade;
    let lobe_t = s.lobe_depth * s.lobes * (s.lobes * theta).cos() * fade;
    let r = taper * flare * bulge * lobe;
    let r_v = taper_d * flare * bulge * lobe
        + taper * flare_d * bulge * lobe
        + taper * flare * bulge_d * lobe
        + taper * flare * bulge * lobe_v;
    let r_t = taper * flare * bulge * lobe_t;
    (r, r_v, r_t)
}

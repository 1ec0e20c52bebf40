//! Per-frame meshing (Akagi §2.2–2.4) on the CPU: topology, watertight joints, unit normals,
//! no degenerate triangles, leaves where their points are.

use glam::{Quat, Vec3};
use rand::{Rng, SeedableRng};
use sylva_core::Tree;
use sylva_core::mesh::{
    DeformLayout, DeformerParams, MeshError, MeshFrame, MeshLayout, MeshParams, RawVertex, deform_radius,
};
use sylva_core::methods::Method;
use sylva_core::pose::Pose;
use sylva_core::species::{PRESETS, SpeciesSource};

fn tree(name: &str) -> Tree {
    SpeciesSource::resolve(name).unwrap().generate(3, &Default::default(), None).unwrap()
}

/// A pose with small random rotations at every joint (seeded).
fn random_pose(t: &Tree, seed: u64, angle: f32) -> Pose {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let delta: Vec<[f32; 4]> = (0..t.segments.len())
        .map(|_| {
            let axis = Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
            Quat::from_axis_angle(axis.normalize_or(Vec3::X), rng.random_range(-angle..angle)).to_array()
        })
        .collect();
    Pose::from_rotations(t, &delta)
}

fn pos(v: &RawVertex) -> Vec3 {
    Vec3::from_array(v.position)
}

/// The checks every mesh must pass (the "watertight tubes" list).
fn check_mesh(t: &Tree, pose: &Pose, layout: &MeshLayout, m: &MeshFrame, what: &str) {
    let h = t.height();
    let sides = layout.params.sides as usize;
    let stride = sides + 1;
    assert_eq!(m.tubes.len(), layout.tube_vertex_count());
    assert_eq!(m.leaves.len(), layout.leaf_vertex_count());
    for (i, v) in m.tubes.iter().chain(&m.leaves).enumerate() {
        let n = v.normal();
        assert!(pos(v).is_finite(), "{what}: vertex {i} not finite");
        assert!((n.length() - 1.0).abs() < 1e-4, "{what}: vertex {i} normal length {}", n.length());
    }
    // The seam column duplicates the first: same position and normal, u = 1 vs 0.
    let uv = layout.tube_uv();
    assert_eq!(uv.len(), layout.tube_vertex_count());
    for r in 0..layout.rings.len() {
        let (a, b) = (&m.tubes[r * stride], &m.tubes[r * stride + sides]);
        assert_eq!(a.position, b.position, "{what}: ring {r} seam open");
        assert_eq!(a.normal_oct, b.normal_oct, "{what}: ring {r} seam's normals");
        assert_eq!((uv[r * stride][0], uv[r * stride + sides][0]), (0.0, 1.0));
    }
    // Rings at joints: the ring shared by two segments is centred on the posed joint, which
    // is where the previous segment's tube ends (its posed end point).
    let params_no_relief = layout.params.bark_depth == 0.0;
    for (r, ring) in layout.rings.iter().enumerate() {
        if ring.t != 0.0 {
            continue;
        }
        let i = ring.segment as usize;
        let centre: Vec3 = (0..sides).map(|k| pos(&m.tubes[r * stride + k])).sum::<Vec3>() / sides as f32;
        let target = if ring.prev != sylva_core::NONE { pose.end(t, ring.prev as usize) } else { pose.start[i] };
        let tol = 2e-5 * h;
        if params_no_relief || ring.relief == 0.0 {
            assert!(
                (centre - target).length() <= tol,
                "{what}: ring {r} of segment {i} centred {} from its joint (tol {tol})",
                (centre - target).length()
            );
        }
    }
    // No degenerate triangles: every triangle has area (relative to its longest edge²).
    for (verts, idx, kind) in [(&m.tubes, &layout.tube_indices, "bark"), (&m.leaves, &layout.leaf_indices, "leaf")] {
        for (f, tri) in idx.chunks(3).enumerate() {
            let [a, b, c] = [0, 1, 2].map(|j| pos(&verts[tri[j] as usize]));
            let area2 = (b - a).cross(c - a).length();
            let longest = (b - a).length().max((c - b).length()).max((a - c).length());
            assert!(area2 > 1e-6 * longest * longest, "{what}: {kind} triangle {f} degenerate");
        }
    }
}

#[test]
fn topology_counts_follow_the_layout() {
    let t = tree("black_tupelo");
    let p = MeshParams::default();
    let l = MeshLayout::new(&t, p).unwrap();
    let rings: usize = t.stems.segment_count.iter().map(|&n| n as usize * p.samples as usize + 1).sum();
    assert_eq!(l.rings.len(), rings);
    // §2.3: a subdivided band has 4 × sides + 1 midpoints and four times the triangles.
    let sides = p.sides as usize;
    let split = l.details.len() / (4 * sides + 1);
    assert_eq!(l.details.len(), split * (4 * sides + 1));
    assert!(split > 0, "the trunk's long quads are subdivided");
    assert_eq!(l.tube_vertex_count(), rings * (sides + 1) + l.details.len());
    assert_eq!(l.tube_indices.len(), (rings - t.stems.len() - split) * sides * 6 + split * sides * 24);
    let plain = MeshLayout::new(&t, MeshParams { subdivide_min_edge: f32::INFINITY, ..p }).unwrap();
    assert!(plain.details.is_empty());
    assert_eq!(plain.tube_indices.len(), (rings - t.stems.len()) * sides * 6);
    assert_eq!(l.leaf_indices.len(), t.leaves.len() * p.leaf_sides as usize * 3);
    assert!(l.tube_indices.iter().all(|&i| (i as usize) < l.tube_vertex_count()));
    assert!(l.leaf_indices.iter().all(|&i| (i as usize) < l.leaf_vertex_count()));
    let no_leaves = MeshLayout::new(&t, MeshParams { leaves: false, ..p }).unwrap();
    assert_eq!(no_leaves.leaf_vertex_count(), 0);
}

#[test]
fn every_preset_meshes_watertight_at_rest_and_posed() {
    for preset in PRESETS {
        let t = tree(preset.name);
        for (k, pose) in [Pose::rest(&t), random_pose(&t, 7, 0.15)].iter().enumerate() {
            let flat = MeshLayout::new(&t, MeshParams { bark_depth: 0.0, ..Default::default() }).unwrap();
            check_mesh(&t, pose, &flat, &flat.mesh(&t, pose), &format!("{} pose {k}", preset.name));
            let bark = MeshLayout::new(&t, MeshParams::default()).unwrap();
            check_mesh(&t, pose, &bark, &bark.mesh(&t, pose), &format!("{} pose {k} with relief", preset.name));
        }
    }
}

#[test]
fn tubes_follow_the_radius_and_relief_stays_within_its_depth() {
    let t = tree("quaking_aspen");
    let pose = Pose::rest(&t);
    for depth in [0.0, 0.06] {
        let l = MeshLayout::new(&t, MeshParams { bark_depth: depth, ..Default::default() }).unwrap();
        let m = l.mesh(&t, &pose);
        let stride = l.params.sides as usize + 1;
        let mut displaced = 0;
        for (r, ring) in l.rings.iter().enumerate() {
            let s = ring.segment as usize;
            let lerp = t.segments.radius_base[s] + (t.segments.radius_tip[s] - t.segments.radius_base[s]) * ring.t;
            let radius = ring.radius;
            assert!(radius >= lerp && radius > 0.0, "ring {r}: radius {radius} below the segment's {lerp}");
            let centre: Vec3 =
                (0..stride - 1).map(|k| pos(&m.tubes[r * stride + k])).sum::<Vec3>() / (stride - 1) as f32;
            for k in 0..stride - 1 {
                let d = (pos(&m.tubes[r * stride + k]) - centre).length();
                let allowed = radius * (1.0 + 1.01 * ring.relief) + 1e-5;
                assert!(d <= allowed, "ring {r}: vertex {k} at {d} m from the centre, radius {radius}");
                if (d - radius).abs() > 1e-3 * radius + 1e-5 {
                    displaced += 1;
                }
            }
        }
        assert_eq!(displaced > 0, depth > 0.0, "relief depth {depth}: {displaced} displaced vertices");
    }
}

#[test]
fn leaves_hang_where_their_points_are_and_move_with_their_segment() {
    let t = tree("quaking_aspen");
    let l = MeshLayout::new(&t, MeshParams::default()).unwrap();
    let stride = l.params.leaf_sides as usize + 1;
    let rest = l.mesh(&t, &Pose::rest(&t));
    let leaf_uv = l.leaf_uv();
    for i in (0..t.leaves.len()).step_by(97) {
        let c = pos(&rest.leaves[i * stride]);
        let want = t.leaves.position[i] + t.leaves.orientation[i] * Vec3::new(0.0, 0.5 * t.leaves.length[i], 0.0);
        assert!((c - want).length() < 1e-5, "leaf {i} centre");
        // The first rim vertex lies on the midrib below the centre, where v = 0 is the
        // attachment point (the disc's half-circles hold its blade, so they start a little
        // below it).
        let r = &rest.leaves[i * stride + 1];
        let [u, v] = leaf_uv[i * stride + 1];
        assert!((u - 0.5).abs() < 1e-6 && v < 0.0 && v > -0.1, "leaf {i} rim start ({u}, {v})");
        let attach = c + (pos(r) - c) * (0.5 / (0.5 - v));
        assert!((attach - t.leaves.position[i]).length() < 1e-5, "leaf {i} attachment");
        let n = rest.leaves[i * stride].normal();
        // Within the octahedral normal's quantisation (under 1e-4, `mesh::vertex`).
        assert!((n - t.leaves.orientation[i] * Vec3::Z).length() < 1e-4);
    }
    // Rigidly rotating the whole tree about its root rotates every leaf with it.
    let q = Quat::from_rotation_z(0.3);
    let mut delta = vec![[0.0, 0.0, 0.0, 1.0]; t.segments.len()];
    delta[0] = q.to_array();
    let posed = l.mesh(&t, &Pose::from_rotations(&t, &delta));
    let root = t.segments.start[0];
    for (a, b) in rest.leaves.iter().zip(&posed.leaves).step_by(31) {
        let want = root + q * (pos(a) - root);
        assert!((pos(b) - want).length() < 1e-4, "leaf vertex did not follow its segment");
    }
}

#[test]
fn bad_parameters_are_refused_with_the_field_named() {
    let t = tree("palm");
    for (p, field) in [
        (MeshParams { sides: 2, ..Default::default() }, "sides"),
        (MeshParams { samples: 0, ..Default::default() }, "samples"),
        (MeshParams { leaf_sides: 1000, ..Default::default() }, "leaf_sides"),
        (MeshParams { bark_depth: f32::NAN, ..Default::default() }, "bark_depth"),
    ] {
        match MeshLayout::new(&t, p) {
            Err(e @ MeshError::Param { .. }) => assert!(e.to_string().contains(field), "{e}"),
            other => panic!("{field}: expected a parameter error, got {other:?}"),
        }
    }
}

#[test]
fn a_forest_layout_meshes_like_its_trees() {
    let (a, b) = (tree("palm"), tree("ternary"));
    let p = MeshParams::default();
    let (la, lb) = (MeshLayout::new(&a, p).unwrap(), MeshLayout::new(&b, p).unwrap());
    let forest = MeshLayout::concat(&[&la, &lb]).unwrap();
    let (pa, pb) = (random_pose(&a, 1, 0.1), random_pose(&b, 2, 0.1));
    let (mut joint, mut acc) = sylva_core::pose::pose_buffers(&a, &pa);
    let (jb, ab) = sylva_core::pose::pose_buffers(&b, &pb);
    joint.extend(jb);
    acc.extend(ab);
    let m = forest.mesh_raw(&joint, &acc);
    let (ma, mb) = (la.mesh(&a, &pa), lb.mesh(&b, &pb));
    // Bark vertices: every tree's ring vertices, then every tree's midpoints (§2.3).
    let stride = p.sides as usize + 1;
    let (ra, rb) = (la.rings.len() * stride, lb.rings.len() * stride);
    assert!(!la.details.is_empty(), "the palm's trunk is subdivided");
    assert_eq!(m.tubes, [&ma.tubes[..ra], &mb.tubes[..rb], &ma.tubes[ra..], &mb.tubes[rb..]].concat());
    assert_eq!(m.leaves, [ma.leaves.clone(), mb.leaves.clone()].concat());
    assert_eq!(forest.triangle_count(), la.triangle_count() + lb.triangle_count());
    // Every forest triangle is its tree's triangle, vertex for vertex.
    let (fa, fb) = forest.tube_indices.split_at(la.tube_indices.len());
    for (mine, theirs, own) in [(fa, &la.tube_indices, &ma.tubes), (fb, &lb.tube_indices, &mb.tubes)] {
        for (i, j) in mine.iter().zip(theirs.iter()) {
            assert_eq!(m.tubes[*i as usize], own[*j as usize]);
        }
    }
    let other = MeshLayout::new(&b, MeshParams { sides: 5, ..p }).unwrap();
    assert!(MeshLayout::concat(&[&la, &other]).is_err());
}

#[test]
fn skinning_follows_the_pose_and_keeps_joint_rings_on_their_joints() {
    use sylva_core::mesh::SkinLayout;
    let t = tree("sassafras");
    let l = MeshLayout::new(&t, MeshParams { bark_depth: 0.0, ..Default::default() }).unwrap();
    let skin = SkinLayout::new(&l);
    let h = t.height();
    // At rest the skinned mesh is the rest mesh.
    let rest = l.mesh(&t, &Pose::rest(&t));
    let (j, a) = sylva_core::pose::pose_buffers(&t, &Pose::rest(&t));
    let same = skin.skin(&j, &a, 1);
    for (x, y) in rest.tubes.iter().zip(&same.tubes).chain(rest.leaves.iter().zip(&same.leaves)) {
        assert!((pos(x) - pos(y)).length() <= 1e-6 * h);
    }
    // Two instances with different poses: each follows its own; leaves exactly as meshed,
    // joint rings centred on the posed joints, normals unit.
    let poses = [random_pose(&t, 5, 0.15), random_pose(&t, 6, 0.15)];
    let (mut joint, mut acc) = (Vec::new(), Vec::new());
    for p in &poses {
        let (j, a) = sylva_core::pose::pose_buffers(&t, p);
        joint.extend(j);
        acc.extend(a);
    }
    let skinned = skin.skin(&joint, &acc, 2);
    let (nt, nl) = (l.tube_vertex_count(), l.leaf_vertex_count());
    let stride = l.params.sides as usize + 1;
    for (k, p) in poses.iter().enumerate() {
        let meshed = l.mesh(&t, p);
        for (x, y) in meshed.leaves.iter().zip(&skinned.leaves[k * nl..(k + 1) * nl]) {
            assert!((pos(x) - pos(y)).length() <= 1e-5 * h, "instance {k}: leaf vertex off");
        }
        let tubes = &skinned.tubes[k * nt..(k + 1) * nt];
        for (r, ring) in l.rings.iter().enumerate() {
            if ring.t == 0.0 {
                let c: Vec3 = (0..stride - 1).map(|j| pos(&tubes[r * stride + j])).sum::<Vec3>() / (stride - 1) as f32;
                let want = p.start[ring.segment as usize];
                assert!((c - want).length() <= 1e-4 * h, "instance {k}: joint ring {r} off by {}", (c - want).length());
            }
        }
    }
    assert_ne!(skinned.leaves[..nl], skinned.leaves[nl..], "the two instances moved alike");
}

mod deformer {
    use super::*;
    use sylva_core::mesh::{DeformLayout, DeformerParams, RawDeformShape, deform_radius};
    use sylva_core::methods::skjermo::{Skjermo, SkjermoParams, bezier};
    use sylva_core::wind::WindScene;

    fn deform(
        layout: &DeformLayout,
        m: &Skjermo,
        state: &[sylva_core::methods::skjermo::RawSkjermoState],
    ) -> Vec<RawVertex> {
        let mut out = vec![bytemuck::Zeroable::zeroed(); layout.vertex_count()];
        sylva_core::mesh::skjermo_deform(&layout.info(), &layout.rings, &layout.shapes, &m.stems, state, &mut out);
        out
    }

    fn curve(m: &Skjermo, state: &[sylva_core::methods::skjermo::RawSkjermoState], k: usize) -> [Vec3; 4] {
        [0, 1, 2, 3].map(|j| Vec3::from_slice(&m.stems[k].rest[j][..3]) + Vec3::from_slice(&state[k].delta[j][..3]))
    }

    /// Without lobes the ring's centroid is the Bézier point (the handles cancel over a
    /// full turn); at the base the ring's radius is r (1 + flare); normals are unit and point
    /// away from the curve — at rest and after the wind has bent the curves.
    #[test]
    fn branches_follow_their_current_bezier() {
        let t = tree("black_tupelo");
        let h = t.height();
        let p = DeformerParams { trunk_lobe_depth: 0.0, ..DeformerParams::for_tree(&t) };
        assert!(p.trunk_flare > 0.0, "the tupelo's flare is exercised");
        let layout = DeformLayout::new(&t, p).unwrap();
        let m = Skjermo::new(&t, SkjermoParams::default());
        let mut state = m.rest_state(&t);
        let wind = WindScene::resolve("gusty").unwrap();
        let fieldswaves = wind.packed();
        let stride = p.sides as usize + 1;
        for round in 0..2 {
            let v = deform(&layout, &m, &state.stems);
            for (r, ring) in layout.rings.iter().enumerate() {
                let k = ring.stem as usize;
                let c = curve(&m, &state.stems, k);
                let centre: Vec3 = (0..stride - 1).map(|j| pos(&v[r * stride + j])).sum::<Vec3>() / (stride - 1) as f32;
                let want = bezier(&c, ring.v);
                assert!(
                    (centre - want).length() <= 1e-4 * h,
                    "round {round} ring {r}: centroid off by {}",
                    (centre - want).length()
                );
                for j in 0..stride {
                    let x = &v[r * stride + j];
                    let n = x.normal();
                    assert!((n.length() - 1.0).abs() < 1e-4);
                    // Rings thinner than f32 resolves at their height are noise.
                    let resolvable = (pos(x) - centre).length() > 64.0 * f32::EPSILON * centre.length();
                    assert!(
                        !resolvable || n.dot(pos(x) - centre) > 0.0,
                        "round {round} ring {r} (stem {k}, v {}, shape {:?}, curve {c:?}): normal points inward",
                        ring.v,
                        layout.shapes[k]
                    );
                }
                if ring.v == 0.0 {
                    let s = &layout.shapes[k];
                    let want_r = s.radius * (1.0 + s.flare);
                    let got = (pos(&v[r * stride]) - centre).length();
                    assert!((got - want_r).abs() <= 1e-3 * want_r + 1e-5, "stem {k}: base radius {got} vs {want_r}");
                }
            }
            // Bend the curves and check again.
            for _ in 0..30 {
                m.step(&t, &fieldswaves, &mut state, 1.0 / 30.0);
            }
            assert!(state.stems.iter().any(|s| s.delta[3][0] != 0.0), "the wind bent nothing");
        }
    }

    /// The Jacobian normals (eq. 10) agree with finite differences of the surface.
    #[test]
    fn jacobian_normals_match_finite_differences() {
        let t = tree("quaking_aspen");
        let p = DeformerParams {
            sides: 64,
            rows_per_segment: 16,
            trunk_flare: 0.6,
            trunk_lobes: 5.0,
            trunk_lobe_depth: 0.1,
            bulges: 3.0,
            bulge_depth: 0.05,
            ..Default::default()
        };
        let layout = DeformLayout::new(&t, p).unwrap();
        let m = Skjermo::new(&t, SkjermoParams::default());
        let state = m.rest_state(&t);
        let v = deform(&layout, &m, &state.stems);
        let stride = p.sides as usize + 1;
        let mut worst = 0.0f32;
        // The trunk (stem 0): rings 1..rows-1, every side.
        let rows = layout.rings.iter().filter(|r| r.stem == 0).count();
        for r in 1..rows - 1 {
            for j in 0..p.sides as usize {
                let at = |rr: usize, jj: usize| pos(&v[rr * stride + (jj + p.sides as usize) % p.sides as usize]);
                let d_theta = at(r, j + 1) - at(r, j + p.sides as usize - 1);
                let d_u = at(r + 1, j) - at(r - 1, j);
                let fd = d_theta.cross(d_u).normalize();
                let n = v[r * stride + j].normal();
                worst = worst.max(1.0 - n.dot(fd));
            }
        }
        assert!(worst < 0.02, "analytic and finite-difference normals differ: 1 − cos = {worst}");
    }

    #[test]
    fn radius_functions_follow_equations_2_to_5() {
        let s = RawDeformShape {
            radius: 0.5,
            taper: 2.0,
            flare: 0.3,
            bulges: 3.0,
            bulge_depth: 0.1,
            lobes: 5.0,
            lobe_depth: 0.2,
            lobe_fade: 1.0,
            v_floor: 0.9f32.powf(0.5),
            _pad: [0.0; 3],
        };
        let (v, th) = (0.3f32, 0.7f32);
        let want = 0.5
            * (1.0 - v * v)
            * (0.3 / 100.0 * 100f32.powf(1.0 - 8.0 * v) + 1.0)
            * (1.0 + 0.1 * (3.0 * std::f32::consts::TAU * v).sin())
            * (1.0 + 0.2 * (5.0 * th).sin() * (1.0 - v));
        let (r, r_v, r_t) = deform_radius(&s, v, th);
        assert!((r - want).abs() < 1e-5, "{r} vs {want}");
        let e = 1e-3;
        let fd_v = (deform_radius(&s, v + e, th).0 - deform_radius(&s, v - e, th).0) / (2.0 * e);
        let fd_t = (deform_radius(&s, v, th + e).0 - deform_radius(&s, v, th - e).0) / (2.0 * e);
        assert!((r_v - fd_v).abs() < 1e-2 * fd_v.abs().max(1.0), "{r_v} vs {fd_v}");
        assert!((r_t - fd_t).abs() < 1e-2 * fd_t.abs().max(1.0), "{r_t} vs {fd_t}");
        // The tip keeps a ring: never below a tenth of the base radius.
        assert!((deform_radius(&s, 1.0, 0.0).0 - 0.05).abs() < 1e-6);
    }
}

#[test]
fn subdivided_bands_are_crack_free_and_displaced_by_the_relief_at_their_midpoints() {
    use std::collections::HashSet;
    let t = tree("quaking_aspen");
    let l = MeshLayout::new(&t, MeshParams::default()).unwrap();
    let m = l.mesh(&t, &random_pose(&t, 11, 0.1));
    let stride = l.params.sides as usize + 1;
    let base = l.rings.len() * stride;
    assert!(!l.details.is_empty());
    // Edges of triangles made of ring vertices only (bands not subdivided).
    let plain: HashSet<(u32, u32)> = l
        .tube_indices
        .chunks(3)
        .filter(|t| t.iter().all(|&i| (i as usize) < base))
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .map(|(a, b)| (a.min(b), a.max(b)))
        .collect();
    let (mut displaced, mut on_boundary) = (0, 0);
    let mut largest = 0.0f32;
    for (k, d) in l.details.iter().enumerate() {
        let (a, b, v) = (&m.tubes[d.a as usize], &m.tubes[d.b as usize], &m.tubes[base + k]);
        let mid = (pos(a) + pos(b)) * 0.5;
        let off = pos(v) - mid;
        if plain.contains(&(d.a.min(d.b), d.a.max(d.b))) {
            // A midpoint on an edge a plain triangle uses stays on that edge: no crack.
            assert_eq!(d.scale, 0.0, "detail {k} on a boundary edge is displaced");
            on_boundary += 1;
        }
        if d.scale == 0.0 {
            assert!(off.length() <= 1e-6 * mid.length().max(1.0), "detail {k} off its edge by {off}");
            continue;
        }
        // Displaced along its normal by at most twice the amplitude (relief is in −1…1).
        let n = v.normal();
        // (f32: positions resolve to about 1e-7 of their distance from the origin.)
        let slack = 1e-3 * off.length() + 4e-7 * mid.length();
        assert!(off.cross(n).length() <= slack, "detail {k} not moved along its normal");
        assert!(off.length() <= 2.0 * d.scale + 1e-6, "detail {k} moved {} > 2 × {}", off.length(), d.scale);
        largest = largest.max(off.length() / d.scale);
        displaced += 1;
    }
    assert!(displaced > 0 && on_boundary > 0, "{displaced} displaced, {on_boundary} on boundaries");
    assert!(largest > 0.2, "the relief between rings adds detail ({largest} of the amplitude at most)");
}

/// Skjermo's deformer flares the trunk once, as the species says: the aspen's deformed base
/// radius (at θ = 0, where its lobes add nothing) over its unflared radius is within 2 % of
/// Weber–Penn's flare at the base, `1 + 0.99 flare`, so it matches the segments' own base
/// radius; the flare is gone by an eighth of the way up.
#[test]
fn the_deformer_flares_the_trunk_once_as_weber_penn_does() {
    let t = tree("quaking_aspen");
    let flare = t.trunk_shape.flare;
    assert!((flare - 0.6).abs() < 1e-6, "the aspen's Weber–Penn flare");
    let layout = DeformLayout::new(&t, DeformerParams::for_tree(&t)).unwrap();
    let s = &layout.shapes[0];
    let unflared = t.segments.radius_base[0] / t.trunk_shape.flare_factor(0.0);
    assert!((s.radius - unflared).abs() <= 1e-6 * unflared, "the grid's radius is the unflared one");
    let (base, _, _) = deform_radius(s, 0.0, 0.0);
    let taper_at = |v: f32| s.radius * (1.0 - v.powf(s.taper));
    let ratio = base / s.radius;
    let weber_penn = 1.0 + flare * 0.99;
    assert!((ratio / weber_penn - 1.0).abs() < 0.02, "deformed / rest base radius {ratio}, Weber–Penn {weber_penn}");
    assert!((base / t.segments.radius_base[0] - 1.0).abs() < 0.02, "matches the segments' base radius");
    let (eighth, _, _) = deform_radius(s, 0.125, 0.0);
    assert!((eighth / taper_at(0.125) - 1.0).abs() < 0.01, "flare {} left at an eighth", eighth / taper_at(0.125));
    // Trees without flare (grammars) keep their radius at the base.
    let g = tree("sympodial");
    assert_eq!(g.trunk_shape, Default::default());
    let layout = DeformLayout::new(&g, DeformerParams::for_tree(&g)).unwrap();
    let (r, _, _) = deform_radius(&layout.shapes[0], 0.0, 0.0);
    assert!((r / g.segments.radius_base[0] - 1.0).abs() < 1e-6, "no flare asked, none added");
}

/// The trunk's cross-section follows the species: round where `lobes = 0` (palm, fir), with
/// the species' lobes and depth elsewhere (the aspen's 5 at 0.07).
#[test]
fn trunk_lobes_come_from_the_species() {
    for p in sylva_core::species::PRESETS.iter().filter(|p| p.kind == sylva_core::species::PresetKind::Species) {
        let t = tree(p.name);
        let layout = DeformLayout::new(&t, DeformerParams::for_tree(&t)).unwrap();
        let s = &layout.shapes[0];
        let radii: Vec<f32> =
            (0..64).map(|k| deform_radius(s, 0.05, k as f32 * std::f32::consts::TAU / 64.0).0).collect();
        let (lo, hi) = radii.iter().fold((f32::MAX, 0.0f32), |(a, b), &r| (a.min(r), b.max(r)));
        let spread = (hi - lo) / (hi + lo);
        let (lobes, depth) = (t.trunk_shape.lobes, t.trunk_shape.lobe_depth);
        if lobes == 0 || depth == 0.0 {
            assert!(spread < 1e-6, "{}: lobes 0, yet the section varies by {spread}", p.name);
        } else {
            // 1 ± depth (1 − 0.05 fade) around the ring.
            let want = depth * 0.95;
            assert!((spread - want).abs() < 0.1 * want + 1e-3, "{}: spread {spread}, want {want}", p.name);
            assert_eq!(s.lobes, lobes as f32, "{}", p.name);
        }
    }
}

/// Zioma §6.5: a stem's base pairs with the branch one step higher in the hierarchy,
/// weighted by distance from the branch's origin and by stiffness; a trunk's base with
/// nothing. Every weight is in [0, ½].
#[test]
fn skinning_pairs_a_stem_base_with_its_parent_branch_by_stiffness() {
    use sylva_core::mesh::SkinLayout;
    use sylva_core::mesh::skin::base_weight;
    let t = tree("black_tupelo");
    let l = MeshLayout::new(&t, MeshParams::default()).unwrap();
    let skin = SkinLayout::new(&l);
    let stride = l.params.sides as usize + 1;
    let (mut bases, mut hinged) = (0, 0);
    for (r, ring) in l.rings.iter().enumerate() {
        let b = skin.tube_skin[r * stride];
        assert!((0.0..=0.5).contains(&b.weight), "ring {r}: weight {}", b.weight);
        let i = ring.segment as usize;
        let p = t.segments.parent[i];
        if ring.t == 0.0 && ring.prev == sylva_core::NONE {
            if p == sylva_core::NONE {
                assert_eq!(b.weight, 0.0, "the trunk's base follows the trunk alone");
                continue;
            }
            bases += 1;
            let w = base_weight(t.segments.stiffness[i], t.segments.stiffness[p as usize]);
            assert_eq!((b.bone1, b.weight), (p, 0.5 * w), "ring {r}: a stem's base ring");
            hinged += usize::from(w < 0.5);
        }
    }
    assert!(bases > 100, "the tupelo has many stems ({bases})");
    assert!(hinged > 0, "some twigs are much more flexible than their parents and hinge");
    assert_eq!(base_weight(1.0, 1.0), 1.0);
    assert!((base_weight(1.0, 9.0) - 0.2).abs() < 1e-6);
    assert_eq!(base_weight(0.0, 0.0), 0.0);
}

//! The renderer: WGSL validated with naga, the uniform struct's layout, and a golden image
//! of a small scene on this machine's adapter (lavapipe in CI).
//!
//! Golden images: `tests/golden/<name>.png`. A render passes when its mean absolute
//! difference from the reference is below [`MEAN_TOLERANCE`] (0–255 scale) — tolerant of
//! rasteriser rounding, not of a missing shadow or a wrong colour. `SYLVA_BLESS=1` rewrites
//! the references; on failure `<name>.actual.png` and `<name>.diff.png` are written next to
//! the reference.

mod common;

use glam::{Mat4, Vec3};
use std::path::PathBuf;
use sylva_core::mesh::{MeshLayout, MeshParams};
use sylva_core::pose::Pose;
use sylva_core::species::SpeciesSource;
use sylva_gpu::mesh::GpuMesh;
use sylva_gpu::render::{Camera, Instance, Lighting, RENDER_WGSL, RawGlobals, RenderSettings, Renderer};

/// Largest mean absolute difference per channel (0–255) from the reference.
const MEAN_TOLERANCE: f64 = 1.5;

#[test]
fn render_wgsl_validates_and_globals_match() {
    let module =
        naga::front::wgsl::parse_str(RENDER_WGSL).unwrap_or_else(|e| panic!("{}", e.emit_to_string(RENDER_WGSL)));
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
        .validate(&module)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(RENDER_WGSL)));
    for entry in ["vs_sky", "fs_sky", "vs_ground", "fs_ground", "vs_tree", "fs_bark", "fs_leaf", "vs_shadow"] {
        assert!(module.entry_points.iter().any(|e| e.name == entry), "no entry point {entry}");
    }
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).unwrap();
    let (handle, _) = module.types.iter().find(|(_, t)| t.name.as_deref() == Some("Globals")).expect("Globals");
    assert_eq!(layouter[handle].size as usize, std::mem::size_of::<RawGlobals>());
}

fn golden_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden")
}

/// Compares `rgba` with the stored reference `name` (see the module docs).
fn check_golden(name: &str, w: u32, h: u32, rgba: &[u8]) {
    let dir = golden_dir();
    let reference = dir.join(format!("{name}.png"));
    let actual = image::RgbaImage::from_raw(w, h, rgba.to_vec()).unwrap();
    if std::env::var("SYLVA_BLESS").is_ok_and(|v| v == "1") {
        actual.save(&reference).unwrap();
        eprintln!("blessed {}", reference.display());
        return;
    }
    let want = image::open(&reference)
        .unwrap_or_else(|e| panic!("{}: {e} (run with SYLVA_BLESS=1 to create it)", reference.display()))
        .to_rgba8();
    assert_eq!(want.dimensions(), (w, h), "{name}: reference size");
    let mut diff = image::RgbaImage::new(w, h);
    let mut sum = 0u64;
    for ((a, b), d) in actual.pixels().zip(want.pixels()).zip(diff.pixels_mut()) {
        let e: [u8; 3] = [0, 1, 2].map(|c| a[c].abs_diff(b[c]));
        sum += e.iter().map(|&x| x as u64).sum::<u64>();
        *d = image::Rgba([e[0].saturating_mul(8), e[1].saturating_mul(8), e[2].saturating_mul(8), 255]);
    }
    let mean = sum as f64 / (w as f64 * h as f64 * 3.0);
    if mean > MEAN_TOLERANCE {
        actual.save(dir.join(format!("{name}.actual.png"))).unwrap();
        diff.save(dir.join(format!("{name}.diff.png"))).unwrap();
        panic!("{name}: mean difference {mean:.3} > {MEAN_TOLERANCE}; wrote {name}.actual.png and {name}.diff.png");
    }
    println!("{name}: mean difference {mean:.3} (tolerance {MEAN_TOLERANCE})");
}

#[test]
fn small_scene_matches_its_golden_image() {
    let Some(ctx) = common::gpu() else { return };
    let t = SpeciesSource::resolve("palm").unwrap().generate(1, &Default::default(), None).unwrap();
    let layout = MeshLayout::new(&t, MeshParams::default()).unwrap();
    let mesh = GpuMesh::new(ctx, &layout).unwrap();
    let (w, h) = (192u32, 128u32);
    let renderer = Renderer::new(ctx, RenderSettings { width: w, height: h, msaa: 4, shadow_size: 512 }).unwrap();
    let camera = Camera { eye: Vec3::new(2.0, 2.5, 9.0), target: Vec3::new(0.0, 2.2, 0.0), fov_y_deg: 45.0 };
    let light = Lighting::default();
    let tint = Vec3::new(0.25, 0.5, 0.1);
    let instances = Renderer::instances(
        ctx,
        &[
            Instance { transform: Mat4::IDENTITY, tint, leaf_shape: t.leaf_shape },
            Instance { transform: Mat4::from_translation(Vec3::new(-4.0, 0.0, -5.0)), tint, leaf_shape: t.leaf_shape },
        ],
    );
    let globals = renderer.globals(&camera, &light, (Vec3::new(-6.0, 0.0, -7.0), Vec3::new(3.0, 5.0, 3.0)));
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    mesh.record_pose(ctx, &mut encoder, &t, &Pose::rest(&t));
    let items = [mesh.draw_item(&instances, 2)];
    renderer.record(ctx, &mut encoder, &globals, &items);
    let rgba = renderer.read_image(ctx, encoder).unwrap();
    assert_eq!(rgba.len(), (w * h * 4) as usize);

    // The tree is there: the same frame without trees differs where the palm stands.
    let empty = renderer.render(ctx, &globals, &[]).unwrap();
    let changed = rgba.chunks(4).zip(empty.chunks(4)).filter(|(a, b)| a[..3] != b[..3]).count();
    let fraction = changed as f64 / (w * h) as f64;
    assert!(fraction > 0.03, "only {:.1} % of pixels show a tree", 100.0 * fraction);
    // Sky above, ground below: the top row is bluer than it is green, the bottom row greener.
    let px = |x: u32, y: u32| &rgba[((y * w + x) * 4) as usize..][..3];
    assert!(px(2, 1)[2] > px(2, 1)[1], "sky is not blue: {:?}", px(2, 1));
    assert!(px(2, h - 2)[1] > px(2, h - 2)[2], "ground is not green: {:?}", px(2, h - 2));
    check_golden("small_scene", w, h, &rgba);
}

/// Skinned instances drawn in batches (the split that keeps a large forest under the binding
/// limit) give the same image as one batch: every instance is drawn once, with its own
/// transform and its own pose.
#[test]
fn skinned_instances_drawn_in_batches_match_one_batch() {
    use sylva_core::mesh::SkinLayout;
    use sylva_gpu::mesh::skin::GpuSkin;
    let Some(ctx) = common::gpu() else { return };
    let t = SpeciesSource::resolve("palm").unwrap().generate(1, &Default::default(), None).unwrap();
    let layout = MeshLayout::new(&t, MeshParams { sides: 6, leaf_sides: 6, ..Default::default() }).unwrap();
    let skin = SkinLayout::new(&layout);
    let (w, h) = (160u32, 96u32);
    let renderer = Renderer::new(ctx, RenderSettings { width: w, height: h, msaa: 1, shadow_size: 256 }).unwrap();
    let camera = Camera { eye: Vec3::new(0.0, 3.0, 14.0), target: Vec3::new(0.0, 2.5, 0.0), fov_y_deg: 45.0 };
    let tint = Vec3::new(0.25, 0.5, 0.1);
    let placed: Vec<Instance> = (0..3)
        .map(|k| Instance {
            transform: Mat4::from_translation(Vec3::new(-5.0 + 5.0 * k as f32, 0.0, 0.0)),
            tint,
            leaf_shape: t.leaf_shape,
        })
        .collect();
    let instances = Renderer::instances(ctx, &placed);
    let globals =
        renderer.globals(&camera, &Lighting::default(), (Vec3::new(-8.0, 0.0, -3.0), Vec3::new(8.0, 6.0, 3.0)));
    // Each instance its own pose: the crown bent by a different angle.
    let (mut joint, mut acc) = (Vec::new(), Vec::new());
    for k in 0..3 {
        let bend = glam::Quat::from_rotation_z(0.15 * k as f32);
        let delta: Vec<[f32; 4]> = (0..t.segments.len())
            .map(|s| if t.segments.parent[s] == sylva_core::NONE { bend.to_array() } else { [0.0, 0.0, 0.0, 1.0] })
            .collect();
        let (j, a) = sylva_core::pose::seam_buffers(&t, &delta);
        joint.extend(j);
        acc.extend(a);
    }
    let jb = sylva_gpu::kernel::upload(ctx, "joints", &joint).unwrap();
    let ab = sylva_gpu::kernel::upload(ctx, "rotations", &acc).unwrap();
    let mut images = Vec::new();
    for max_batch in [u32::MAX, 1] {
        let g = GpuSkin::with_max_batch(ctx, &layout, &skin, 3, max_batch).unwrap();
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        g.record(ctx, &mut encoder, &jb, &ab);
        renderer.record(ctx, &mut encoder, &globals, &g.draw_items(&instances));
        images.push(renderer.read_image(ctx, encoder).unwrap());
    }
    let empty = renderer.render(ctx, &globals, &[]).unwrap();
    let trees = images[0].chunks(4).zip(empty.chunks(4)).filter(|(a, b)| a[..3] != b[..3]).count();
    assert!(trees > (w * h / 50) as usize, "only {trees} pixels show trees");
    let differ = images[0].chunks(4).zip(images[1].chunks(4)).filter(|(a, b)| a[..3] != b[..3]).count();
    assert_eq!(differ, 0, "{differ} pixels differ between one batch and three");
}

/// The renderer cuts each leaf to the outline its shape names, as the CPU twin
/// (`LeafShape::contains`, which the exported texture's alpha follows): one 2 m leaf per
/// shape, facing a distant camera, compared pixel by pixel away from the outline's edge.
#[test]
fn the_renderer_cuts_every_leaf_shape_as_the_cpu_outline() {
    use glam::{DQuat, DVec3};
    use sylva_core::model::{LeafDraft, LeafShape, TreeBuilder, WoodProperties};
    let Some(ctx) = common::gpu() else { return };
    let (w, h) = (96u32, 96u32);
    let renderer = Renderer::new(ctx, RenderSettings { width: w, height: h, msaa: 1, shadow_size: 256 }).unwrap();
    // The leaf's square spans x ∈ [−1, 1], y ∈ [50, 52] at z = 0; the view 2.6 m across.
    let half = 1.3f32;
    let camera = Camera {
        eye: Vec3::new(0.0, 51.0, 200.0),
        target: Vec3::new(0.0, 51.0, 0.0),
        fov_y_deg: (2.0 * (half / 200.0).atan()).to_degrees(),
    };
    let globals =
        renderer.globals(&camera, &Lighting::default(), (Vec3::new(-1.0, 50.0, -1.0), Vec3::new(1.0, 52.0, 1.0)));
    let empty = renderer.render(ctx, &globals, &[]).unwrap();
    for shape in LeafShape::ALL {
        let mut b = TreeBuilder::default();
        let stem = b.add_stem(None, 0);
        let base = DVec3::new(0.0, 50.0, 0.0);
        b.push_segment(stem, base, base + DVec3::Y * 0.01, DQuat::IDENTITY, 0.001, 0.001);
        b.leaves.push(LeafDraft {
            stem,
            segment: 0,
            position: base,
            orientation: DQuat::IDENTITY,
            width: 2.0,
            length: 2.0,
        });
        let mut t = b.build("leaf", 1, WoodProperties::default()).unwrap();
        t.leaf_shape = shape;
        let layout = MeshLayout::new(&t, MeshParams { leaf_sides: 16, ..Default::default() }).unwrap();
        let mesh = GpuMesh::new(ctx, &layout).unwrap();
        let instances = Renderer::instances(
            ctx,
            &[Instance { transform: Mat4::IDENTITY, tint: Vec3::new(0.3, 0.5, 0.1), leaf_shape: shape }],
        );
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        mesh.record_pose(ctx, &mut encoder, &t, &Pose::rest(&t));
        renderer.record(ctx, &mut encoder, &globals, &[mesh.draw_item(&instances, 1)]);
        let rgba = renderer.read_image(ctx, encoder).unwrap();
        // Pixel centre → (u, v) on the leaf's square.
        let uv = |x: f32, y: f32| {
            let wx = (x - w as f32 / 2.0) / (h as f32 / 2.0) * half;
            let wy = 51.0 - (y - h as f32 / 2.0) / (h as f32 / 2.0) * half;
            (wx / 2.0 + 0.5, (wy - 50.0) / 2.0)
        };
        let (mut checked, mut wrong, mut blade) = (0, 0, 0);
        for y in 0..h {
            for x in 0..w {
                let (u, v) = uv(x as f32 + 0.5, y as f32 + 0.5);
                let inside = shape.contains(u, v);
                // Away from the edge (1.5 pixels) and from the stub of stem at the base.
                let p = 1.5 * 2.0 * half / h as f32 / 2.0;
                let near = [(-p, 0.0), (p, 0.0), (0.0, -p), (0.0, p)]
                    .iter()
                    .any(|(du, dv)| shape.contains(u + du, v + dv) != inside);
                if near || ((u - 0.5).abs() < 0.05 && v.abs() < 0.05) {
                    continue;
                }
                let i = ((y * w + x) * 4) as usize;
                let drawn = rgba[i..i + 3] != empty[i..i + 3];
                checked += 1;
                blade += inside as usize;
                wrong += (drawn != inside) as usize;
            }
        }
        println!("{:<6}: {blade} blade pixels, {wrong} of {checked} disagree", shape.name());
        assert!(
            blade > 100 && wrong == 0,
            "{}: {wrong} of {checked} pixels disagree with the CPU outline",
            shape.name()
        );
    }
}

//! Weber–Penn leaf shapes: each outline as documented in `model::leaf_shape`, distinct from
//! the others, held by its mesh polygon at every size, cut by the exported texture, read
//! from species files by name or index, and drawn in a golden image.
//!
//! Golden image: `tests/golden/leaf_shapes.png`, one cell per shape (index order, left to
//! right, base at the bottom, the (u, v) square and 0.15 around it): the blade (the exported
//! texture's alpha) in green, the mesh polygon at 8 sides in white. It passes when at most 0.5 % of its pixels differ;
//! `SYLVA_BLESS=1` rewrites it, and a failure writes `leaf_shapes.actual.png` beside it.

use std::path::PathBuf;
use sylva_core::model::LeafShape;
use sylva_core::model::leaf_shape::leaf_rim;

const N: usize = 200;

/// The blade's mask on an N × N grid of (u, v) cell centres.
fn mask(shape: LeafShape) -> Vec<bool> {
    (0..N * N).map(|i| shape.contains(((i % N) as f32 + 0.5) / N as f32, ((i / N) as f32 + 0.5) / N as f32)).collect()
}

/// Whether (u, v) is inside the fan of rim points about (0.5, 0.5).
fn in_polygon(rim: &[(f32, f32)], u: f32, v: f32) -> bool {
    let n = rim.len();
    (0..n).any(|k| {
        let (a, b, c) = ((0.5, 0.5), rim[k], rim[(k + 1) % n]);
        let cross = |p: (f32, f32), q: (f32, f32), r: (f32, f32)| (q.0 - p.0) * (r.1 - p.1) - (q.1 - p.1) * (r.0 - p.0);
        let (d1, d2, d3) = (cross(a, b, (u, v)), cross(b, c, (u, v)), cross(c, a, (u, v)));
        let eps = 1e-6;
        (d1 >= -eps && d2 >= -eps && d3 >= -eps) || (d1 <= eps && d2 <= eps && d3 <= eps)
    })
}

#[test]
fn every_outline_is_held_by_its_mesh_polygon_at_every_size() {
    let mut bad = Vec::new();
    for shape in LeafShape::ALL {
        let m = mask(shape);
        for sides in [6u32, 8, 12, 16, 32] {
            let rim: Vec<(f32, f32)> = (0..sides).map(|k| shape.rim(k, sides)).collect();
            assert!(
                (rim[0].0 - 0.5).abs() < 1e-6 && rim[0].1 < 0.5,
                "{shape:?}: the rim starts below the centre, on the midrib"
            );
            // From 8 sides on, the rim stays within 0.15 of the square (the sampler clamps to its
            // clear border beyond).
            let reach = rim.iter().map(|p| (p.0 - 0.5).abs().max((p.1 - 0.5).abs())).fold(0.0, f32::max);
            assert!(sides < 8 || reach <= 0.65, "{shape:?} at {sides} sides reaches {reach}: {rim:?}");
            let outside = (0..N * N)
                .filter(|&i| {
                    m[i] && !in_polygon(&rim, ((i % N) as f32 + 0.5) / N as f32, ((i / N) as f32 + 0.5) / N as f32)
                })
                .count();
            println!("{:<6} {sides:>2} sides: {outside} blade cells outside", shape.name());
            if outside > 0 {
                bad.push(format!("{} at {sides} sides: {outside} blade cells outside the polygon", shape.name()));
            }
            // Not much more polygon than blade at 16 sides: the leaf's overdraw stays small.
            if sides == 16 {
                let poly = (0..N * N)
                    .filter(|&i| in_polygon(&rim, ((i % N) as f32 + 0.5) / N as f32, ((i / N) as f32 + 0.5) / N as f32))
                    .count();
                let blade = m.iter().filter(|&&b| b).count();
                println!(
                    "{:<6}: blade {:.1} % of the square, polygon at 16 sides {:.2}× the blade",
                    shape.name(),
                    100.0 * blade as f64 / (N * N) as f64,
                    poly as f64 / blade as f64
                );
                assert!(
                    poly as f64 <= 1.6 * blade as f64,
                    "{}: polygon {poly} cells for a blade of {blade}",
                    shape.name()
                );
            }
        }
    }
}

#[test]
fn each_outline_is_distinct_and_as_documented() {
    let masks: Vec<Vec<bool>> = LeafShape::ALL.iter().map(|&s| mask(s)).collect();
    for i in 0..masks.len() {
        for j in 0..i {
            let both = masks[i].iter().zip(&masks[j]).filter(|(a, b)| **a && **b).count();
            let either = masks[i].iter().zip(&masks[j]).filter(|(a, b)| **a || **b).count();
            let iou = both as f64 / either as f64;
            assert!(iou < 0.9, "{} and {} overlap {iou:.2}", LeafShape::ALL[i].name(), LeafShape::ALL[j].name());
        }
    }
    // Width across the blade at height v, and its widest, as fractions of the square.
    let width =
        |s: LeafShape, v: f32| (0..N).filter(|&x| s.contains((x as f32 + 0.5) / N as f32, v)).count() as f32 / N as f32;
    let widest = |s: LeafShape| (1..100).map(|k| width(s, k as f32 / 100.0)).fold(0.0, f32::max);
    let area = |s: LeafShape| mask(s).iter().filter(|&&b| b).count() as f32 / (N * N) as f32;
    use LeafShape::*;
    // Narrow ellipse 0.44 as wide as long; needle a tenth; palm a third.
    assert!((widest(Disc2) - 0.44).abs() < 0.02, "disc2 {}", widest(Disc2));
    assert!((widest(Needle) - 0.10).abs() < 0.02, "needle {}", widest(Needle));
    assert!(widest(Palm) < 0.34 && widest(Palm) > 0.2, "palm {}", widest(Palm));
    // Wide ellipse: nearly round, π/4 of the square. Rounded square: most of it.
    assert!((area(Disc3) - std::f32::consts::FRAC_PI_4 * 0.94 * 0.98).abs() < 0.02, "disc3 {}", area(Disc3));
    assert!(area(Square) > 0.8, "square {}", area(Square));
    // Rounded triangle: wider below the middle than above it.
    assert!(width(Disc1, 0.3) > 1.5 * width(Disc1, 0.75), "disc1 {} {}", width(Disc1, 0.3), width(Disc1, 0.75));
    // Star: five lobes, the radius peaking five times around.
    let peaks = (0..720)
        .filter(|&k| {
            let r = |d: i32| Star.radius(std::f32::consts::TAU * (k + d) as f32 / 720.0);
            r(0) > r(-1) && r(0) >= r(1) && r(0) > 0.4
        })
        .count();
    assert_eq!(peaks, 5, "star lobes");
    // Heart: notched at the petiole, pointed at the tip.
    assert!(Heart.radius(std::f32::consts::PI) < 0.5 * Heart.radius(std::f32::consts::PI - 0.6));
    assert!(Heart.radius(0.0) > Heart.radius(0.3));
    // The disc is the blade the renderer has always cut.
    assert!((widest(Disc) - 0.87).abs() < 0.03, "disc {}", widest(Disc));
}

#[test]
fn species_files_name_a_shape_or_give_its_index() {
    use sylva_core::species::SpeciesSource;
    let text = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../presets/species/quaking_aspen.toml"),
    )
    .unwrap();
    for (value, want) in [
        ("\"star\"", LeafShape::Star),
        ("\"Heart\"", LeafShape::Heart),
        ("4", LeafShape::Square),
        ("0", LeafShape::Disc),
    ] {
        let t = text.replace("leaf_shape = \"disc\"", &format!("leaf_shape = {value}"));
        let src = SpeciesSource::from_text(&t, "aspen.toml").unwrap_or_else(|e| panic!("{value}: {e}"));
        let tree = src.generate(1, &Default::default(), None).unwrap();
        assert_eq!(tree.leaf_shape, want);
        let raw = tree.raw_leaves()[0];
        assert_eq!(raw.shape, want.index());
    }
    for (value, want) in
        [("9", "leaf_shape 9 is outside 0–8"), ("\"oval\"", "unknown leaf_shape `oval`, expected one of disc, disc1")]
    {
        let t = text.replace("leaf_shape = \"disc\"", &format!("leaf_shape = {value}"));
        let e = SpeciesSource::from_text(&t, "aspen.toml").map(|_| ()).unwrap_err().to_string();
        assert!(e.contains("aspen.toml:") && e.contains(want), "{value}: {e}");
    }
    // The shipped species carry theirs into the tree.
    for (name, want) in
        [("palm", LeafShape::Palm), ("balsam_fir", LeafShape::Needle), ("weeping_willow", LeafShape::Disc2)]
    {
        let tree = SpeciesSource::resolve(name).unwrap().generate(1, &Default::default(), None).unwrap();
        assert_eq!(tree.leaf_shape, want, "{name}");
    }
}

#[test]
fn the_exported_leaf_texture_cuts_the_shape() {
    for shape in LeafShape::ALL {
        let png = sylva_core::export::textures::leaf_png(shape);
        let img = image::load_from_memory(&png).unwrap().to_rgba8();
        let n = img.width();
        let (mut agree, mut total) = (0usize, 0usize);
        for (x, y, p) in img.enumerate_pixels() {
            let (u, v) = ((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32);
            // Away from the one-pixel soft edge, alpha is the outline.
            let inside = shape.contains(u, v);
            let near = [(-1.5, 0.0), (1.5, 0.0), (0.0, -1.5), (0.0, 1.5)]
                .iter()
                .any(|(du, dv)| shape.contains(u + du / n as f32, v + dv / n as f32) != inside);
            let border = x == 0 || y == 0 || x == n - 1 || y == n - 1;
            if border {
                assert_eq!(p[3], 0, "{}: the border is clear", shape.name());
            } else if !near {
                total += 1;
                agree += ((p[3] == 255) == inside && (p[3] == 0) != inside) as usize;
            }
        }
        // The palm's teeth are cusps, sharper than the soft edge's one-pixel band.
        assert!(
            total - agree <= total / 5000,
            "{}: texture alpha disagrees with the outline at {} pixels",
            shape.name(),
            total - agree
        );
    }
}

#[test]
fn leaf_shapes_match_their_golden_image() {
    const CELL: u32 = 96;
    let cols = LeafShape::ALL.len() as u32;
    let mut img = image::RgbaImage::from_pixel(CELL * cols, CELL, image::Rgba([24, 24, 32, 255]));
    for (c, shape) in LeafShape::ALL.iter().enumerate() {
        let rim: Vec<(f32, f32)> = (0..8).map(|k| leaf_rim(shape.index(), k, 8)).collect();
        for y in 0..CELL {
            for x in 0..CELL {
                // The square and 0.15 around it; v up the cell.
                let u = -0.15 + 1.3 * (x as f32 + 0.5) / CELL as f32;
                let v = 1.15 - 1.3 * (y as f32 + 0.5) / CELL as f32;
                let px = img.get_pixel_mut(c as u32 * CELL + x, y);
                if shape.contains(u, v) {
                    *px = image::Rgba([70, 150, 50, 255]);
                }
                let d = 1.3 / CELL as f32;
                let edge = [(d, 0.0), (0.0, d)]
                    .iter()
                    .any(|(du, dv)| in_polygon(&rim, u, v) != in_polygon(&rim, u + du, v + dv));
                if edge {
                    *px = image::Rgba([235, 235, 235, 255]);
                }
            }
        }
    }
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden");
    let reference = dir.join("leaf_shapes.png");
    if std::env::var("SYLVA_BLESS").is_ok_and(|v| v == "1") {
        img.save(&reference).unwrap();
        return;
    }
    let want = image::open(&reference)
        .unwrap_or_else(|e| panic!("{}: {e} (SYLVA_BLESS=1 creates it)", reference.display()))
        .to_rgba8();
    assert_eq!(want.dimensions(), img.dimensions());
    let differ = img.pixels().zip(want.pixels()).filter(|(a, b)| a != b).count();
    let share = differ as f64 / (img.width() * img.height()) as f64;
    if share > 0.005 {
        img.save(dir.join("leaf_shapes.actual.png")).unwrap();
        panic!("leaf_shapes: {:.2} % of pixels differ; wrote leaf_shapes.actual.png", 100.0 * share);
    }
}

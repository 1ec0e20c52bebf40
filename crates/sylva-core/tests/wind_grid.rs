//! Grid wind fields (Zioma §6.3.1's wind texture): interpolation, tiling, scrolling, frames,
//! the file layouts, the shipped example and what a bad grid file is told.

use glam::Vec3;
use rand::{Rng, SeedableRng};
use std::path::Path;
use sylva_core::wind::{Grid, GridData, WindField, WindScene};

fn scene(g: Grid) -> WindScene {
    WindScene { fields: vec![WindField::Grid(g)] }
}

/// An affine velocity field, for nodes and for the truth between them.
fn affine(p: Vec3, t: f32) -> Vec3 {
    Vec3::new(1.0 + 0.3 * p.x - 0.2 * p.y + 0.05 * p.z + 0.5 * t, -0.4 + 0.1 * p.z, 2.0 - 0.07 * p.x + 0.2 * p.y)
}

/// A 3-D grid over `affine` at 1 / `rate` s a frame: its nodes at origin + (x, y, z) · cell.
fn affine_grid(rate: f32) -> Grid {
    let (size, frames, cell, origin) = ([6u32, 4, 5], 3u32, Vec3::new(2.0, 1.5, 3.0), Vec3::new(-4.0, 0.5, 2.0));
    let mut nodes = Vec::new();
    for k in 0..frames {
        for z in 0..size[2] {
            for y in 0..size[1] {
                for x in 0..size[0] {
                    let p = origin + Vec3::new(x as f32, y as f32, z as f32) * cell;
                    nodes.push(affine(p, k as f32 / rate).to_array());
                }
            }
        }
    }
    let mut g = Grid::new(GridData::new(size, frames, nodes).unwrap(), cell.to_array());
    (g.origin, g.frame_rate, g.wrap) = (origin.to_array(), rate, false);
    g
}

#[test]
fn a_grid_reproduces_an_affine_field_between_its_nodes_and_frames() {
    let g = affine_grid(2.0);
    let (lo, hi) = (Vec3::from_array(g.origin), Vec3::from_array(g.origin) + Vec3::new(10.0, 4.5, 12.0));
    let wind = scene(g).packed();
    let mut rng = rand::rngs::StdRng::seed_from_u64(3);
    let mut worst = 0.0f32;
    for _ in 0..20_000 {
        let p = Vec3::new(rng.random_range(lo.x..hi.x), rng.random_range(lo.y..hi.y), rng.random_range(lo.z..hi.z));
        let t = rng.random_range(0.0..1.0); // within frames 0–2 at 2 frames/s
        worst = worst.max((wind.at(p, t) - affine(p, t)).length());
    }
    // Trilinear interpolation of an affine field is exact; f32 rounding of values up to ~8 m/s.
    assert!(worst < 2e-5, "largest error {worst} m/s");
    // Held at the edge outside it: beyond the +x face the +x face's value.
    let p = Vec3::new(hi.x + 30.0, 2.0, 5.0);
    assert!((wind.at(p, 0.0) - affine(Vec3::new(hi.x, 2.0, 5.0), 0.0)).length() < 2e-5);
}

#[test]
fn frames_loop_and_a_wrapped_grid_tiles_and_moves_with_its_scroll() {
    let mut g = affine_grid(2.0);
    g.wrap = true;
    let period = Vec3::new(6.0 * 2.0, 4.0 * 1.5, 5.0 * 3.0);
    g.scroll = [3.0, 0.0, -1.5];
    let scroll = Vec3::from_array(g.scroll);
    let wind = scene(g).packed();
    let mut rng = rand::rngs::StdRng::seed_from_u64(4);
    for _ in 0..5_000 {
        let p = Vec3::new(rng.random_range(-50.0..50.0), rng.random_range(0.0..20.0), rng.random_range(-50.0..50.0));
        let t = rng.random_range(0.0..10.0);
        let v = wind.at(p, t);
        // One tile over along each axis; the pattern carried by the scroll; 3 frames at 2/s loop in 1.5 s.
        for shift in [Vec3::X * period.x, Vec3::Y * period.y, Vec3::Z * period.z] {
            assert!((wind.at(p + shift, t) - v).length() < 1e-3, "tile at {p} {t}");
        }
        assert!((wind.at(p + scroll * 1.5, t + 1.5) - v).length() < 1e-3, "scroll and loop at {p} {t}");
    }
    // Halfway between two frames is halfway between their values.
    let p = Vec3::new(1.0, 1.0, 4.0);
    let (a, b) = (scene(affine_grid(2.0)).packed().at(p, 0.5), scene(affine_grid(2.0)).packed().at(p, 1.0));
    let mid = scene(affine_grid(2.0)).packed().at(p, 0.75);
    assert!((mid - (a + b) * 0.5).length() < 1e-5 && (a - b).length() > 0.2);
}

#[test]
fn a_one_layer_grid_is_the_same_at_every_height() {
    let nodes = (0..16).map(|i| [i as f32, 0.0, -(i as f32)]).collect();
    let wind = scene(Grid::new(GridData::new([4, 1, 4], 1, nodes).unwrap(), [1.0, 1.0, 1.0])).packed();
    for y in [-5.0, 0.0, 0.3, 7.5, 100.0] {
        assert_eq!(wind.at(Vec3::new(1.5, y, 2.25), 3.0), wind.at(Vec3::new(1.5, 0.0, 2.25), 3.0));
    }
    // Between nodes 1 and 2 along x, 2 and 3 along z: 0.5 · (1 + 2) ... bilinear.
    let v = wind.at(Vec3::new(1.5, 0.0, 2.25), 0.0);
    assert!((v.x - (1.5 + 4.0 * 2.25)).abs() < 1e-5, "{v}");
}

#[test]
fn grid_files_round_trip_as_raw_and_as_png() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(5);
    let nodes: Vec<[f32; 3]> = (0..5 * 3 * 2).map(|_| [0; 3].map(|_| rng.random_range(-3.0..3.0))).collect();
    let g = GridData::new([5, 1, 3], 2, nodes).unwrap();
    assert_eq!(GridData::from_raw(&g.to_raw()).unwrap(), g);
    let back = GridData::from_png(&g.to_png(4.0).unwrap(), 4.0, 2).unwrap();
    assert_eq!((back.size, back.frames), (g.size, g.frames));
    // 16 bits over ±4 m/s: half a step is 4 / 65535.
    for (a, b) in back.nodes.iter().zip(&g.nodes) {
        assert!((Vec3::from_array(*a) - Vec3::from_array(*b)).abs().max_element() <= 4.0 / 65535.0 + 1e-6);
    }
}

#[test]
fn the_eddies_preset_tiles_carries_unit_eddies_and_has_no_divergence() {
    // Read by name: from the crate's directory, where presets/wind/eddies.png is not, so the
    // shipped copy is what loads.
    let scene = WindScene::resolve("eddies").unwrap();
    let grid = scene.fields.iter().find_map(|f| if let WindField::Grid(g) = f { Some(g.clone()) } else { None });
    let grid = grid.expect("a grid field");
    assert_eq!((grid.data.size, grid.data.frames), ([64, 1, 64], 8));
    let wind = WindScene { fields: vec![WindField::Grid(grid.clone())] }.packed();
    let mut rng = rand::rngs::StdRng::seed_from_u64(6);
    let (mut speed2, mut div2, mut grad2, n) = (0.0f64, 0.0f64, 0.0f64, 4_000);
    let h = 0.5;
    for _ in 0..n {
        let p = Vec3::new(rng.random_range(-300.0..300.0), 2.0, rng.random_range(-300.0..300.0));
        let t = rng.random_range(0.0..60.0);
        let v = wind.at(p, t);
        speed2 += (v.x * v.x + v.z * v.z) as f64;
        let dx = (wind.at(p + Vec3::X * h, t) - wind.at(p - Vec3::X * h, t)) / (2.0 * h);
        let dz = (wind.at(p + Vec3::Z * h, t) - wind.at(p - Vec3::Z * h, t)) / (2.0 * h);
        div2 += ((dx.x + dz.z) as f64).powi(2);
        grad2 += ((dx.x * dx.x + dz.z * dz.z + dx.z * dx.z + dz.x * dz.x) / 4.0) as f64;
    }
    let rms = (speed2 / n as f64).sqrt();
    // Unit rms eddies times the preset's scale (1.5), to the 16-bit storage and interpolation.
    assert!((rms / grid.scale as f64 - 1.0).abs() < 0.15, "rms {rms}");
    // The curl of a stream function: divergence a small part of the velocity gradients
    // (what is left is the bilinear interpolation's).
    let ratio = (div2 / grad2).sqrt();
    println!("eddies: rms {rms:.3} m/s, rms divergence / rms gradient {ratio:.3}");
    assert!(ratio < 0.2, "divergence ratio {ratio}");
    // Tiles every 160 m (64 nodes 2.5 m apart), loops every 16 s (8 frames at 0.5/s).
    let p = Vec3::new(13.7, 1.0, -41.2);
    let scroll = Vec3::from_array(grid.scroll);
    assert!((wind.at(p + Vec3::X * 160.0 + scroll * 16.0, 16.0 + 3.0) - wind.at(p, 3.0)).length() < 1e-3);
}

/// A wind file in a temporary directory with a grid field, its grid file written as `bytes`.
fn try_grid(extra: &str, file: &str, bytes: Option<&[u8]>) -> String {
    let dir = tempfile::tempdir().unwrap();
    if let Some(b) = bytes {
        std::fs::write(dir.path().join(file), b).unwrap();
    }
    let text = format!("# wind\n[[field]]\nkind = \"grid\"\nfile = \"{file}\"\ncell = [1.0, 1.0, 1.0]\n{extra}");
    let path = dir.path().join("w.toml");
    std::fs::write(&path, text).unwrap();
    let e = WindScene::load(&path).map(|_| ()).unwrap_err().to_string();
    e.replace(&format!("{}/", dir.path().display()), "")
}

#[test]
fn bad_grid_files_name_the_wind_file_s_line_the_grid_and_the_problem() {
    let g = GridData::new([4, 1, 2], 1, vec![[1.0, 0.0, 0.0]; 8]).unwrap();
    let raw = g.to_raw();
    let cases: Vec<(&str, &str, Option<Vec<u8>>, &str)> = vec![
        ("", "gone.swg", None, "w.toml:4: field[0].file: gone.swg: No such file"),
        ("", "g.swg", Some(b"not a grid at all, truly not".to_vec()), "g.swg: does not start with SYLVAWG1"),
        (
            "",
            "g.swg",
            Some(raw[..raw.len() - 4].to_vec()),
            "g.swg: is 116 bytes; its header (nx 4 ny 1 nz 2 frames 1) needs 120",
        ),
        (
            "",
            "g.swg",
            Some({
                let mut b = raw.clone();
                b[24 + 12 * 5 + 4..24 + 12 * 5 + 8].copy_from_slice(&f32::NAN.to_le_bytes());
                b
            }),
            "node (x 1, y 0, z 1, frame 0) is [1.0, NaN, 0.0], expected finite",
        ),
        (
            "",
            "g.swg",
            Some({
                let mut b = raw.clone();
                b[8..12].copy_from_slice(&5000u32.to_le_bytes());
                b
            }),
            "nx = 5000 is outside [1, 4096] (limit on a grid's side)",
        ),
        (
            "",
            "g.swg",
            Some({
                let mut b = raw.clone();
                for i in 0..4 {
                    b[8 + 4 * i..12 + 4 * i].copy_from_slice(&512u32.to_le_bytes());
                }
                b
            }),
            "= 68719476736 nodes is over the 4194304 node limit",
        ),
        ("range = 4.0\n", "g.swg", Some(raw.clone()), "`range` and `frames` are for PNG grids"),
        ("", "g.png", Some(g.to_png(4.0).unwrap()), "g.png: a PNG grid needs `range` (m/s)"),
        (
            "range = 4.0\nframes = 3\n",
            "g.png",
            Some(g.to_png(4.0).unwrap()),
            "g.png: is 2 pixels high, not a whole number of 3 stacked frames",
        ),
        ("range = 4.0\n", "g.png", Some(raw.clone()), "g.png: is not a PNG grid"),
        (
            "range = 0.0\n",
            "g.png",
            Some(g.to_png(4.0).unwrap()),
            "w.toml:6: field[0].range: 0 is outside [0.001, 1000]",
        ),
        ("scroll = [1.0, nan, 0.0]\n", "g.swg", Some(raw.clone()), "field[0].scroll: NaN is not a finite number"),
    ];
    for (extra, file, bytes, want) in cases {
        let e = try_grid(extra, file, bytes.as_deref());
        assert!(e.contains(want), "{file} {extra:?}: {e}\n  expected it to contain: {want}");
        assert!(e.starts_with("w.toml:"), "names the wind file and line: {e}");
    }
    // A grey PNG is refused by what it is.
    let grey = image::GrayImage::from_raw(2, 2, vec![0, 64, 128, 255]).unwrap();
    let mut png = std::io::Cursor::new(Vec::new());
    grey.write_to(&mut png, image::ImageFormat::Png).unwrap();
    let e = try_grid("range = 1.0\n", "grey.png", Some(png.get_ref()));
    assert!(e.contains("is L8, expected RGB or RGBA"), "{e}");
    assert!(!Path::new("gone.swg").exists());
}

#[test]
fn a_grid_scene_round_trips_through_toml_and_reloads_its_file() {
    let dir = tempfile::tempdir().unwrap();
    let g = GridData::new([3, 2, 2], 2, (0..24).map(|i| [i as f32, 0.5, -1.0]).collect()).unwrap();
    std::fs::write(dir.path().join("g.swg"), g.to_raw()).unwrap();
    let text = "[[field]]\nkind = \"grid\"\nfile = \"g.swg\"\ncell = [2.0, 3.0, 2.0]\nscroll = [1.0, 0.0, 0.0]\nwrap = false\n";
    let path = dir.path().join("w.toml");
    std::fs::write(&path, text).unwrap();
    let scene = WindScene::load(&path).unwrap();
    let WindField::Grid(read) = &scene.fields[0] else { panic!() };
    assert_eq!(*read.data, g);
    std::fs::write(&path, scene.to_toml()).unwrap();
    assert_eq!(WindScene::load(&path).unwrap(), scene);
}

//! Procedural textures shipped inside exported files: a tileable bark colour map and a
//! leaf colour map whose alpha cuts the blade's outline (the tree's leaf shape). Deterministic (the same bytes
//! every run), so exported files are reproducible.
//!
//! Coordinates follow the meshes: bark `u` runs once around the stem and `v` along it (both
//! repeat); a leaf's `u` runs across the blade (0.5 the midrib) and `v` from the base
//! (image row 0) to the tip (the last row).

use crate::model::LeafShape;
use crate::model::leaf_shape::disc_half_width;
use crate::wind::noise::hash_unit;
use std::f32::consts::TAU;

/// Side of each texture, pixels.
pub const TEXTURE_SIZE: u32 = 256;

/// Value noise on a `period × period` lattice that wraps, so the texture tiles.
fn tiled_noise(x: f32, y: f32, period: u32, seed: u32) -> f32 {
    let (fx, fy) = (x * period as f32, y * period as f32);
    let (ix, iy) = (fx.floor(), fy.floor());
    let (tx, ty) = (fx - ix, fy - iy);
    let (sx, sy) = (tx * tx * (3.0 - 2.0 * tx), ty * ty * (3.0 - 2.0 * ty));
    let at = |i: f32, j: f32| {
        let i = (i as i64).rem_euclid(period as i64) as u32;
        let j = (j as i64).rem_euclid(period as i64) as u32;
        hash_unit(i.wrapping_mul(73_856_093) ^ j.wrapping_mul(19_349_663) ^ seed)
    };
    let a = at(ix, iy) + (at(ix + 1.0, iy) - at(ix, iy)) * sx;
    let b = at(ix, iy + 1.0) + (at(ix + 1.0, iy + 1.0) - at(ix, iy + 1.0)) * sx;
    a + (b - a) * sy
}

fn encode_png(pixels: &[u8], color: image::ExtendedColorType) -> Vec<u8> {
    use image::ImageEncoder;
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(pixels, TEXTURE_SIZE, TEXTURE_SIZE, color)
        .expect("encoding a PNG into memory cannot fail");
    out
}

/// Bark ridges (0…1) and fine grain (0…1) at (u, v): seven ridges around the stem, as the
/// mesh's relief, wandering with height.
fn bark_height(u: f32, v: f32) -> (f32, f32) {
    let wander = tiled_noise(u, v, 4, 11) - 0.5;
    let ridge = (TAU * (7.0 * u + 0.6 * wander)).sin().abs().powf(0.6);
    let grain = tiled_noise(u, v, 32, 23) * 0.5 + tiled_noise(u, v, 64, 37) * 0.5;
    (ridge, grain)
}

/// A tangent-space normal map (RGB PNG) of the height field `h` (in texels of relief per
/// texel), by central differences that wrap: +x along `u`, +y along `v`, +z out.
fn normal_map(h: impl Fn(f32, f32) -> f32, strength: f32) -> Vec<u8> {
    let n = TEXTURE_SIZE;
    let d = 1.0 / n as f32;
    let mut px = Vec::with_capacity((n * n * 3) as usize);
    for y in 0..n {
        for x in 0..n {
            let (u, v) = (x as f32 * d, y as f32 * d);
            let du = (h((u + d) % 1.0, v) - h((u - d + 1.0) % 1.0, v)) * 0.5 * strength;
            let dv = (h(u, (v + d) % 1.0) - h(u, (v - d + 1.0) % 1.0)) * 0.5 * strength;
            let nrm = glam::Vec3::new(-du, -dv, 1.0).normalize();
            px.extend(nrm.to_array().iter().map(|c| ((c * 0.5 + 0.5) * 255.0).round() as u8));
        }
    }
    encode_png(&px, image::ExtendedColorType::Rgb8)
}

/// Bark normal map: the relief of [`bark_png`]'s ridges and grain.
pub fn bark_normal_png() -> Vec<u8> {
    normal_map(
        |u, v| {
            let (ridge, grain) = bark_height(u, v);
            ridge + 0.15 * grain
        },
        12.0,
    )
}

/// Leaf normal map of a shape: the midrib and veins raised.
pub fn leaf_normal_png(shape: LeafShape) -> Vec<u8> {
    normal_map(|u, v| leaf_veins(shape, u, v).0, 12.0)
}

/// How far (u, v) lies inside the blade's edge, in (u, v) units (negative outside), and the
/// blade's half-width there for the veins to fade across.
fn blade_edge(shape: LeafShape, u: f32, v: f32) -> (f32, f32) {
    if shape == LeafShape::Disc {
        let half = disc_half_width(v);
        return (half - (u - 0.5).abs(), half);
    }
    let (x, y) = (u - 0.5, v - 0.5);
    ((shape.radius(x.atan2(y)) - (x * x + y * y).sqrt()), 0.5)
}

/// Midrib + veins (0…1) and the blade's coverage (0…1) at (u, v).
fn leaf_veins(shape: LeafShape, u: f32, v: f32) -> (f32, f32) {
    let n = TEXTURE_SIZE as f32;
    let across = (u - 0.5).abs();
    let (inside, half) = blade_edge(shape, u, v);
    let edge = (inside * n + 0.5).clamp(0.0, 1.0);
    let midrib = (1.0 - across * n / 2.5).max(0.0);
    // Veins leave the midrib toward the tip at about 45°.
    let s = (v - across * 0.9) * 9.0;
    let f = s - s.floor();
    let vein = (1.0 - f.min(1.0 - f) * 14.0).clamp(0.0, 1.0) * 0.5;
    ((midrib * 0.6 + vein * (1.0 - across / half.max(1e-3)).max(0.0)).min(1.0) * edge, edge)
}

/// Bark: grey-brown furrows running along the stem (seven ridges around it, as the mesh's
/// relief), broken by noise; RGB PNG.
pub fn bark_png() -> Vec<u8> {
    let n = TEXTURE_SIZE;
    let mut px = Vec::with_capacity((n * n * 3) as usize);
    for y in 0..n {
        for x in 0..n {
            let (u, v) = (x as f32 / n as f32, y as f32 / n as f32);
            let (ridge, grain) = bark_height(u, v);
            let lum = 0.20 + 0.28 * ridge + 0.16 * grain;
            let moss = (tiled_noise(u, v, 8, 51) - 0.62).max(0.0) * 0.6;
            let rgb = [lum * 1.05 - moss * 0.2, lum * 0.92 + moss * 0.3, lum * 0.78 - moss * 0.1];
            px.extend(rgb.iter().map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8));
        }
    }
    encode_png(&px, image::ExtendedColorType::Rgb8)
}

/// An RGBA leaf texture: `blade(u, v)` gives the veins' lightness (0…1), the coverage (alpha,
/// 0…1) and how much of the pixel is twig (0…1); leaf green shaded by noise, twig brown, and
/// a clear one-pixel border (leaf polygons and cards reach the square's edge, and a sampler
/// that clamps to the edge shows nothing there).
fn leaf_rgba(blade: impl Fn(f32, f32) -> (f32, f32, f32)) -> Vec<u8> {
    let n = TEXTURE_SIZE;
    let mut px = Vec::with_capacity((n * n * 4) as usize);
    for y in 0..n {
        for x in 0..n {
            let (u, v) = ((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32);
            let (light, cover, twig) = blade(u, v);
            let cover = if x == 0 || y == 0 || x == n - 1 || y == n - 1 { 0.0 } else { cover };
            let shade = 0.85 + 0.15 * tiled_noise(u, v, 16, 71);
            let leaf = [(0.16 + 0.20 * light) * shade, (0.38 + 0.25 * light) * shade, (0.08 + 0.12 * light) * shade];
            let bark = [0.30, 0.24, 0.17];
            let rgb: [f32; 3] = std::array::from_fn(|k| leaf[k] + (bark[k] - leaf[k]) * twig);
            px.extend(rgb.iter().map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8));
            px.push((cover * 255.0).round() as u8);
        }
    }
    encode_png(&px, image::ExtendedColorType::Rgba8)
}

/// Leaf: green blade with a lighter midrib and veins, alpha 255 inside the outline and 0
/// outside the shape's outline (a one-pixel soft edge); RGBA PNG.
pub fn leaf_png(shape: LeafShape) -> Vec<u8> {
    leaf_rgba(|u, v| {
        let (light, edge) = leaf_veins(shape, u, v);
        (light, edge, 0.0)
    })
}

/// The leaves drawn on a leaf card: (attachment u, attachment v, angle from +v in rad).
/// Four blades, each half the card's side, fanning from a twig up the middle: a card of
/// side `s` carries the leaf area of four blades of side `s / 2`, one blade of side `s`.
pub const CARD_LEAVES: [(f32, f32, f32); 4] = [(0.5, 0.36, 0.6), (0.5, 0.36, -0.6), (0.5, 0.1, 1.2), (0.5, 0.1, -1.2)];

/// What a leaf card shows at (u, v): veins (0…1) and coverage (0…1) of the topmost blade,
/// and the twig's coverage.
fn card_sample(shape: LeafShape, u: f32, v: f32) -> (f32, f32, f32) {
    let mut out = (0.0, 0.0, 0.0);
    for &(au, av, angle) in &CARD_LEAVES {
        let (dx, dy) = (u - au, v - av);
        let (s, c) = angle.sin_cos();
        // Blade coordinates: across (u) and along (v) a blade of side ½ turned by `angle`.
        let (lu, lv) = ((dx * c - dy * s) * 2.0 + 0.5, (dx * s + dy * c) * 2.0);
        if (0.0..=1.0).contains(&lu) && (0.0..=1.0).contains(&lv) {
            let (light, edge) = leaf_veins(shape, lu, lv);
            if edge > out.1 {
                out = (light, edge, 0.0);
            }
        }
    }
    let twig = ((0.012 - (u - 0.5).abs()) * TEXTURE_SIZE as f32 + 0.5).clamp(0.0, 1.0) * f32::from(v < 0.4);
    (out.0, out.1.max(twig), if out.1 < 0.5 { twig } else { 0.0 })
}

/// Leaf card: four blades of the shape on a twig ([`CARD_LEAVES`]), alpha 0 around them and
/// on a clear border; RGBA PNG. Game exports carry several leaves per alpha-masked quad.
pub fn leaf_card_png(shape: LeafShape) -> Vec<u8> {
    leaf_rgba(|u, v| card_sample(shape, u, v))
}

/// Leaf card normal map: the blades' midribs and veins raised.
pub fn leaf_card_normal_png(shape: LeafShape) -> Vec<u8> {
    normal_map(|u, v| card_sample(shape, u, v).0, 12.0)
}

//! Leaf cards: a square, alpha-masked quad per kept leaf, carrying the card texture's four
//! blades on a twig (`textures::leaf_card_png`). Two triangles stand for what the blade
//! polygons of four leaves would draw, as game trees are built.

use super::*;

/// Vertices per card: its corners.
pub(super) const CARD_VERTICES: usize = 4;

/// The rest geometry and bones of the cards of `leaves` (one card each; 4 vertices, 2
/// triangles). A card's side is the geometric mean of its leaf's width and length (the leaf
/// area a thinned leaf stands for, see [`MeshLayout::thin_leaves`]): its four blades of half
/// that side carry the kept leaf's area. The bottom edge's midpoint is the leaf's attachment,
/// the card turns in the leaf's rest frame, and `v` runs from the attachment (0) to the top.
pub(super) fn cards(leaves: &[RawLeaf]) -> (Vec<RawVertex>, Vec<Uv>, Vec<RawSkin>, Vec<u32>) {
    let mut vertices = Vec::with_capacity(leaves.len() * CARD_VERTICES);
    let mut uv = Vec::with_capacity(leaves.len() * CARD_VERTICES);
    let mut skin = Vec::with_capacity(leaves.len() * CARD_VERTICES);
    let mut indices = Vec::with_capacity(leaves.len() * 6);
    for (k, l) in leaves.iter().enumerate() {
        let q = Quat::from_array(l.orientation);
        let (x, y, normal) = (q * Vec3::X, q * Vec3::Y, q * Vec3::Z);
        let side = (l.width.max(0.0) * l.length.max(0.0)).sqrt();
        let base = Vec3::from_array(l.position);
        for (u, v) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
            let p = base + x * ((u - 0.5) * side) + y * (v * side);
            vertices.push(RawVertex::new(p, normal));
            uv.push([u, v]);
            skin.push(RawSkin { bone0: l.segment, bone1: l.segment, weight: 0.0, leaf: l.index + 1 });
        }
        let c = (k * CARD_VERTICES) as u32;
        indices.extend_from_slice(&[c, c + 1, c + 2, c, c + 2, c + 3]);
    }
    (vertices, uv, skin, indices)
}

//! Determinism digest: SHA-256 over every array of a tree.

use super::Tree;
use sha2::{Digest, Sha256};

pub(super) fn digest(t: &Tree) -> String {
    let mut h = Sha256::new();
    h.update(t.name.as_bytes());
    h.update(t.seed.to_le_bytes());
    h.update([t.levels]);
    let s = &t.segments;
    h.update(bytemuck::cast_slice::<u32, u8>(&s.parent));
    h.update(&s.level);
    h.update(bytemuck::cast_slice::<u32, u8>(&s.stem));
    h.update(bytemuck::cast_slice::<glam::Vec3, u8>(&s.start));
    h.update(bytemuck::cast_slice::<glam::Quat, u8>(&s.orientation));
    h.update(bytemuck::cast_slice::<glam::Quat, u8>(&s.local_orientation));
    for v in [&s.length, &s.radius_base, &s.radius_tip, &s.mass, &s.stiffness] {
        h.update(bytemuck::cast_slice::<f32, u8>(v));
    }
    let st = &t.stems;
    for v in [&st.parent, &st.first_segment, &st.segment_count] {
        h.update(bytemuck::cast_slice::<u32, u8>(v));
    }
    h.update(&st.level);
    for v in [&st.attach, &st.length, &st.bezier_error] {
        h.update(bytemuck::cast_slice::<f32, u8>(v));
    }
    for b in &st.bezier {
        h.update(bytemuck::cast_slice::<glam::Vec3, u8>(b));
    }
    let l = &t.leaves;
    h.update(bytemuck::cast_slice::<u32, u8>(&l.segment));
    h.update(bytemuck::cast_slice::<glam::Vec3, u8>(&l.position));
    h.update(bytemuck::cast_slice::<glam::Quat, u8>(&l.orientation));
    h.update(bytemuck::cast_slice::<f32, u8>(&l.width));
    h.update(bytemuck::cast_slice::<f32, u8>(&l.length));
    let c = &t.children;
    for v in [&c.offset, &c.count, &c.index, &c.leaf_offset, &c.leaf_count] {
        h.update(bytemuck::cast_slice::<u32, u8>(v));
    }
    let out = h.finalize();
    out.iter().map(|b| format!("{b:02x}")).collect()
}

//! Static Wavefront OBJ of a tree at rest: an n-sided tube per stem (rings shared between
//! consecutive segments) and a two-sided quad per leaf. Enough to look at a generated tree in
//! any viewer; the full meshers (Akagi tubes, Skjermo deformer) live in the meshing module.

use crate::io::write_atomic;
use crate::model::Tree;
use glam::{Quat, Vec3};
use std::io::{self, Write};
use std::path::Path;

/// OBJ options.
#[derive(Debug, Clone, Copy)]
pub struct ObjOptions {
    /// Sides of each tube cross-section.
    pub sides: u32,
    /// Include leaves.
    pub leaves: bool,
}

impl Default for ObjOptions {
    fn default() -> Self {
        Self { sides: 6, leaves: true }
    }
}

/// Writes the tree as OBJ (atomically). Returns (vertices, triangles).
pub fn write_obj(tree: &Tree, path: &Path, opts: ObjOptions) -> io::Result<(usize, usize)> {
    let mut counts = (0, 0);
    write_atomic(path, |w| {
        counts = obj(tree, w, opts)?;
        Ok(())
    })?;
    Ok(counts)
}

fn ring(w: &mut dyn Write, centre: Vec3, q: Quat, r: f32, sides: u32) -> io::Result<()> {
    for k in 0..sides {
        let a = k as f32 / sides as f32 * std::f32::consts::TAU;
        let p = centre + q * Vec3::new(a.cos() * r, 0.0, a.sin() * r);
        writeln!(w, "v {} {} {}", p.x, p.y, p.z)?;
    }
    Ok(())
}

fn obj(t: &Tree, w: &mut dyn Write, opts: ObjOptions) -> io::Result<(usize, usize)> {
    let sides = opts.sides.max(3);
    let s = &t.segments;
    writeln!(
        w,
        "# Sylva tree `{}`, seed {}: {} segments, {} stems, {} leaves",
        t.name,
        t.seed,
        s.len(),
        t.stems.len(),
        t.leaves.len()
    )?;
    writeln!(w, "o bark")?;
    let mut v = 0usize;
    let mut faces = 0usize;
    for k in 0..t.stems.len() {
        let first = t.stems.first_segment[k] as usize;
        let n = t.stems.segment_count[k] as usize;
        let base_v = v + 1;
        for i in first..first + n {
            ring(w, s.start[i], s.orientation[i], s.radius_base[i], sides)?;
        }
        let last = first + n - 1;
        ring(w, s.end(last), s.orientation[last], s.radius_tip[last], sides)?;
        v += (n + 1) * sides as usize;
        for r in 0..n {
            for j in 0..sides as usize {
                let a = base_v + r * sides as usize + j;
                let b = base_v + r * sides as usize + (j + 1) % sides as usize;
                let c = a + sides as usize;
                let d = b + sides as usize;
                writeln!(w, "f {a} {c} {d}\nf {a} {d} {b}")?;
                faces += 2;
            }
        }
    }
    if opts.leaves && !t.leaves.is_empty() {
        writeln!(w, "o leaves")?;
        let l = &t.leaves;
        for i in 0..l.len() {
            let q = l.orientation[i];
            let hw = 0.5 * l.width[i];
            for c in [
                Vec3::new(-hw, 0.0, 0.0),
                Vec3::new(hw, 0.0, 0.0),
                Vec3::new(hw, l.length[i], 0.0),
                Vec3::new(-hw, l.length[i], 0.0),
            ] {
                let p = l.position[i] + q * c;
                writeln!(w, "v {} {} {}", p.x, p.y, p.z)?;
            }
            let a = v + 1;
            writeln!(w, "f {} {} {} {}\nf {} {} {} {}", a, a + 1, a + 2, a + 3, a + 3, a + 2, a + 1, a)?;
            v += 4;
            faces += 4;
        }
    }
    Ok((v, faces))
}

//! Wind on a grid (Zioma §6.3.1: "a 2-D texture" of wind over the terrain, or the slices a
//! GPU fluid solver writes): velocities at the nodes of a regular grid, read from a file,
//! sampled bilinearly (one layer) or trilinearly, scrolling with a velocity and stepping
//! through looped frames (linear between them).
//!
//! Node (x, y, z) of frame k sits at `origin + (x, y, z) · cell + scroll · t` at time
//! `k / frame_rate`. Outside the grid the nodes repeat (`wrap`, a tile) or the edge holds.
//!
//! Two file layouts:
//!
//! * **Raw** (`.swg`, any other extension): `SYLVAWG1` (8 bytes), then `nx ny nz frames` as
//!   little-endian u32, then `nx·ny·nz·frames` velocities (x, y, z) in m/s as
//!   little-endian f32, x fastest, then y, z and frame: what a solver's slices dump as they are.
//! * **PNG** (`.png`), one layer: 8- or 16-bit RGB(A); R, G, B = x, y, z (y up), with
//!   `v = (2 c / c_max − 1) · range`; image width `nx`, height `nz · frames` (frames stacked
//!   top to bottom, row 0 = z 0). Alpha is ignored.
//!
//! Packed (`raw`): the field record holds `a` = (origin, frame rate), `b` = (1 / cell,
//! wrap); the first record of its wave table holds (nx, ny, nz, frames) in `dir` and the
//! scroll in `k`; the nodes follow, three to a record (`dir`, `k`, `phase`).

use crate::wind::raw::{RawField, RawWave};
use glam::Vec3;
use serde::{Deserialize, Serialize};
use std::io::Read;
use std::path::Path;
use std::sync::Arc;

/// Magic bytes of a raw grid file.
pub const MAGIC: &[u8; 8] = b"SYLVAWG1";
/// Largest grid: nodes over all frames (64 MiB on the device).
pub const MAX_GRID_NODES: u64 = 1 << 22;
/// Largest number of nodes along one axis, and of frames.
pub const MAX_GRID_SIDE: u32 = 4096;

/// A grid field as a wind file names it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Grid {
    /// The grid file, relative to the wind file (see the module for the layouts).
    pub file: String,
    /// Where node (0, 0, 0) sits at t = 0, m.
    #[serde(default)]
    pub origin: [f32; 3],
    /// Node spacing along x, y and z, m (y is unused by a one-layer grid).
    pub cell: [f32; 3],
    /// Velocity the whole grid moves with, m/s: the mean wind, for frozen turbulence.
    #[serde(default)]
    pub scroll: [f32; 3],
    /// Frames per second when the file holds several; they loop.
    #[serde(default = "frame_rate")]
    pub frame_rate: f32,
    /// Outside the grid, repeat it (a tile) or hold its edge.
    #[serde(default = "yes")]
    pub wrap: bool,
    /// Multiplies every velocity.
    #[serde(default = "one")]
    pub scale: f32,
    /// PNG only: the speed a channel's full swing stands for, m/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range: Option<f32>,
    /// PNG only: frames stacked in the image (its height is `nz · frames`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frames: Option<u32>,
    /// The nodes, read from `file` when the wind file is read.
    #[serde(skip)]
    pub data: Arc<GridData>,
}

fn frame_rate() -> f32 {
    10.0
}
fn yes() -> bool {
    true
}
fn one() -> f32 {
    1.0
}

/// The nodes of a grid: `size` = (nx, ny, nz), `frames`, and velocities (m/s) indexed
/// `((frame · nz + z) · ny + y) · nx + x`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct GridData {
    /// Nodes along x, y, z.
    pub size: [u32; 3],
    /// Frames.
    pub frames: u32,
    /// Velocities, m/s.
    pub nodes: Vec<[f32; 3]>,
}

impl GridData {
    /// Checks the sizes against the limits and the node count, and every value for NaN.
    pub fn new(size: [u32; 3], frames: u32, nodes: Vec<[f32; 3]>) -> Result<Self, String> {
        let count = Self::count(size, frames)?;
        if nodes.len() as u64 != count {
            return Err(format!("{} nodes for a grid of {count}", nodes.len()));
        }
        if let Some(i) = nodes.iter().position(|v| v.iter().any(|c| !c.is_finite())) {
            let [nx, ny, nz] = size.map(|n| n as usize);
            let (x, y, z, k) = (i % nx, i / nx % ny, i / (nx * ny) % nz, i / (nx * ny * nz));
            return Err(format!("node (x {x}, y {y}, z {z}, frame {k}) is {:?}, expected finite velocities", nodes[i]));
        }
        Ok(Self { size, frames, nodes })
    }

    /// Nodes in a grid of `size` and `frames`, within the limits.
    fn count(size: [u32; 3], frames: u32) -> Result<u64, String> {
        for (n, name) in size.iter().chain([&frames]).zip(["nx", "ny", "nz", "frames"]) {
            if *n == 0 || *n > MAX_GRID_SIDE {
                return Err(format!("{name} = {n} is outside [1, {MAX_GRID_SIDE}] (limit on a grid's side)"));
            }
        }
        let count = size.iter().chain([&frames]).map(|&n| n as u64).product::<u64>();
        if count > MAX_GRID_NODES {
            return Err(format!(
                "{}×{}×{}×{} = {count} nodes is over the {MAX_GRID_NODES} node limit on a grid",
                size[0], size[1], size[2], frames
            ));
        }
        Ok(count)
    }

    /// Reads the raw layout.
    pub fn from_raw(bytes: &[u8]) -> Result<Self, String> {
        if bytes.len() < 24 || &bytes[..8] != MAGIC {
            return Err("does not start with SYLVAWG1 and a 16-byte size, expected a raw grid (or a .png)".into());
        }
        let word = |i: usize| u32::from_le_bytes(bytes[8 + 4 * i..12 + 4 * i].try_into().expect("4 bytes"));
        let (size, frames) = ([word(0), word(1), word(2)], word(3));
        let count = Self::count(size, frames)?;
        let want = 24 + 12 * count;
        if bytes.len() as u64 != want {
            return Err(format!(
                "is {} bytes; its header (nx {} ny {} nz {} frames {frames}) needs {want}",
                bytes.len(),
                size[0],
                size[1],
                size[2]
            ));
        }
        let f = |i: usize| f32::from_le_bytes(bytes[24 + 4 * i..28 + 4 * i].try_into().expect("4 bytes"));
        Self::new(size, frames, (0..count as usize).map(|i| [f(3 * i), f(3 * i + 1), f(3 * i + 2)]).collect())
    }

    /// The raw layout.
    pub fn to_raw(&self) -> Vec<u8> {
        let mut out = MAGIC.to_vec();
        for n in self.size.iter().chain([&self.frames]) {
            out.extend(n.to_le_bytes());
        }
        out.extend(self.nodes.iter().flatten().flat_map(|c| c.to_le_bytes()));
        out
    }

    /// Reads a PNG of `frames` stacked one-layer frames, channels spanning ±`range` m/s.
    pub fn from_png(bytes: &[u8], range: f32, frames: u32) -> Result<Self, String> {
        let mut reader = image::ImageReader::with_format(std::io::Cursor::new(bytes), image::ImageFormat::Png);
        let mut limits = image::Limits::default();
        limits.max_image_width = Some(MAX_GRID_SIDE);
        limits.max_image_height = Some(MAX_GRID_SIDE * frames.max(1));
        limits.max_alloc = Some(MAX_GRID_NODES * 16);
        reader.limits(limits);
        let image = reader.decode().map_err(|e| format!("is not a PNG grid: {e}"))?;
        use image::ColorType::*;
        if !matches!(image.color(), Rgb8 | Rgba8 | Rgb16 | Rgba16) {
            return Err(format!("is {:?}, expected RGB or RGBA with 8 or 16 bits a channel", image.color()));
        }
        let (w, h) = (image.width(), image.height());
        if frames == 0 || h % frames != 0 {
            return Err(format!("is {h} pixels high, not a whole number of {frames} stacked frames"));
        }
        let rgb = image.to_rgb32f();
        let nodes = rgb.pixels().map(|p| p.0.map(|c| (2.0 * c - 1.0) * range)).collect();
        Self::new([w, 1, h / frames], frames, nodes)
    }

    /// A 16-bit PNG of a one-layer grid, channels spanning ±`range` m/s (values beyond it clip).
    pub fn to_png(&self, range: f32) -> Result<Vec<u8>, String> {
        if self.size[1] != 1 {
            return Err(format!("a PNG holds one layer; this grid has {}", self.size[1]));
        }
        let (w, h) = (self.size[0], self.size[2] * self.frames);
        let q = |v: f32| ((v / range * 0.5 + 0.5).clamp(0.0, 1.0) * 65535.0).round() as u16;
        let raw: Vec<u16> = self.nodes.iter().flat_map(|v| v.map(q)).collect();
        let image = image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(w, h, raw).ok_or("grid size")?;
        let mut out = std::io::Cursor::new(Vec::new());
        image.write_to(&mut out, image::ImageFormat::Png).map_err(|e| e.to_string())?;
        Ok(out.into_inner())
    }
}

/// Reads at most `limit` bytes of a file, saying so when it is longer.
pub fn read_limited(path: &Path, limit: u64) -> Result<Vec<u8>, String> {
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let mut bytes = Vec::new();
    file.take(limit + 1).read_to_end(&mut bytes).map_err(|e| e.to_string())?;
    if bytes.len() as u64 > limit {
        return Err(format!("is over the {limit} byte limit on a grid file"));
    }
    Ok(bytes)
}

/// Largest grid file: the raw layout at [`MAX_GRID_NODES`].
pub const MAX_GRID_FILE_BYTES: u64 = 24 + 12 * MAX_GRID_NODES;

impl Grid {
    /// A grid field over `data` with node spacing `cell`, at rest at the origin, wrapped.
    pub fn new(data: GridData, cell: [f32; 3]) -> Self {
        Self {
            file: String::new(),
            origin: [0.0; 3],
            cell,
            scroll: [0.0; 3],
            frame_rate: frame_rate(),
            wrap: true,
            scale: 1.0,
            range: None,
            frames: None,
            data: Arc::new(data),
        }
    }

    /// Whether `file` is read as a PNG.
    pub fn is_png(&self) -> bool {
        Path::new(&self.file).extension().is_some_and(|e| e.eq_ignore_ascii_case("png"))
    }

    /// Reads `file` through `read` (which resolves it) into `data`: the file's problem, or
    /// what the layout needs that the field lacks.
    pub fn load(&mut self, read: impl Fn(&str) -> Result<Vec<u8>, String>) -> Result<(), String> {
        let bytes = read(&self.file)
            .map_err(|e| format!("{}: {e}; expected a grid file (raw `SYLVAWG1` or `.png`)", self.file))?;
        let data = if self.is_png() {
            let range = self.range.ok_or_else(|| format!("{}: a PNG grid needs `range` (m/s)", self.file))?;
            GridData::from_png(&bytes, range, self.frames.unwrap_or(1))
        } else if self.range.is_some() || self.frames.is_some() {
            return Err(format!("{}: `range` and `frames` are for PNG grids; a raw grid carries its own", self.file));
        } else {
            GridData::from_raw(&bytes)
        };
        self.data = Arc::new(data.map_err(|e| format!("{}: {e}", self.file))?);
        Ok(())
    }

    /// The packed record and its table (see the module); an empty grid packs as still air.
    pub fn pack(&self, r: &mut RawField, waves: &mut Vec<RawWave>) {
        let d = &self.data;
        if d.nodes.is_empty() {
            return;
        }
        r.kind = crate::wind::raw::kind::GRID;
        r.a = [self.origin[0], self.origin[1], self.origin[2], self.frame_rate];
        r.b = [1.0 / self.cell[0], 1.0 / self.cell[1], 1.0 / self.cell[2], if self.wrap { 1.0 } else { 0.0 }];
        let [nx, ny, nz] = d.size.map(|n| n as f32);
        waves.push(RawWave {
            dir: [nx, ny, nz, d.frames as f32],
            k: [self.scroll[0], self.scroll[1], self.scroll[2], 0.0],
            phase: [0.0; 4],
        });
        let s = self.scale;
        let node = |i: usize| d.nodes.get(i).map_or([0.0; 4], |v| [v[0] * s, v[1] * s, v[2] * s, 0.0]);
        waves.extend((0..d.nodes.len().div_ceil(3)).map(|j| RawWave {
            dir: node(3 * j),
            k: node(3 * j + 1),
            phase: node(3 * j + 2),
        }));
    }
}

/// One axis of a lookup: the two nodes either side of `u` (in nodes) and the fraction
/// between them, over `n` nodes repeated or held at the edge. As `grid_axis` in `wind.wgsl`.
#[inline]
fn axis(u: f32, n: f32, wrap: bool) -> (u32, u32, f32) {
    if wrap {
        let fl = u.floor();
        let m = n as i32;
        let i = ((fl as i32) % m + m) % m;
        (i as u32, ((i + 1) % m) as u32, u - fl)
    } else {
        let c = u.clamp(0.0, n - 1.0);
        let fl = c.floor();
        let i = fl as u32;
        (i, (i + 1).min(n as u32 - 1), c - fl)
    }
}

/// Velocity of a packed grid field at `p` and `t`: trilinear in space (bilinear for one
/// layer, whose y weight is between equal nodes), linear between looped frames. As
/// `grid_at` in `wind.wgsl`, same operations in the same order.
pub fn grid_at(f: &RawField, waves: &[RawWave], p: Vec3, t: f32) -> Vec3 {
    let head = &waves[f.wave_offset as usize];
    let n = head.dir;
    let wrap = f.b[3] >= 0.5;
    let g = ((p - Vec3::new(f.a[0], f.a[1], f.a[2])) - Vec3::new(head.k[0], head.k[1], head.k[2]) * t)
        * Vec3::new(f.b[0], f.b[1], f.b[2]);
    let (ax, ay, az) = (axis(g.x, n[0], wrap), axis(g.y, n[1], wrap), axis(g.z, n[2], wrap));
    let at = axis(t * f.a[3], n[3], true);
    let (nx, ny, nz) = (n[0] as u32, n[1] as u32, n[2] as u32);
    let base = f.wave_offset as usize + 1;
    let node = |i: u32| {
        let w = &waves[base + (i / 3) as usize];
        let v = match i % 3 {
            0 => w.dir,
            1 => w.k,
            _ => w.phase,
        };
        Vec3::new(v[0], v[1], v[2])
    };
    let lerp = |a: Vec3, b: Vec3, s: f32| a + (b - a) * s;
    let frame = |k: u32| {
        let row = |z: u32, y: u32| {
            let at = ((k * nz + z) * ny + y) * nx;
            lerp(node(at + ax.0), node(at + ax.1), ax.2)
        };
        let plane = |z: u32| lerp(row(z, ay.0), row(z, ay.1), ay.2);
        lerp(plane(az.0), plane(az.1), az.2)
    };
    lerp(frame(at.0), frame(at.1), at.2)
}

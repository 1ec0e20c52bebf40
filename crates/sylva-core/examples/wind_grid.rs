//! Writes `presets/wind/eddies.png`, the example wind grid: a tileable, divergence-free
//! field of eddies over the ground (the curl of a random periodic stream function), 64 × 64
//! nodes and 8 looping frames, unit rms speed, stored as a 16-bit PNG spanning ±4 m/s.
//!
//! `cargo run -p sylva-core --example wind_grid -- presets/wind/eddies.png`

use std::f64::consts::TAU;
use sylva_core::rng::Stream;
use sylva_core::wind::GridData;

const N: u32 = 64;
const FRAMES: u32 = 8;
const RANGE: f32 = 4.0;

fn main() -> Result<(), String> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "presets/wind/eddies.png".into());
    // Stream function ψ = Σ a sin(2π(kx x + kz z)/N + φ + 2π m k/F): integer wavenumbers
    // tile, integer m loop over the frames; amplitude ∝ |k|^(-2) puts the energy in large eddies.
    let mut rng = Stream::new(0x6564_6479);
    let modes: Vec<(f64, f64, f64, f64, f64)> = (0..48)
        .map(|_| {
            let kx = (rng.unit() * 9.0).floor() - 4.0;
            let kz = (rng.unit() * 9.0).floor() - 4.0;
            let k2 = (kx * kx + kz * kz).max(1.0);
            (kx, kz, 1.0 / k2, rng.unit() * TAU, (rng.unit() * 3.0).floor() - 1.0)
        })
        .collect();
    let mut nodes = Vec::with_capacity((N * N * FRAMES) as usize);
    for k in 0..FRAMES {
        for z in 0..N {
            for x in 0..N {
                // u = ∂ψ/∂z, w = −∂ψ/∂x (nodes apart): no divergence.
                let (mut u, mut w) = (0.0, 0.0);
                for &(kx, kz, a, phase, m) in &modes {
                    let th =
                        TAU * (kx * x as f64 + kz * z as f64) / N as f64 + phase + TAU * m * k as f64 / FRAMES as f64;
                    let c = a * th.cos() * TAU / N as f64;
                    u += c * kz;
                    w -= c * kx;
                }
                nodes.push([u, 0.0, w]);
            }
        }
    }
    let rms = (nodes.iter().map(|v| v[0] * v[0] + v[2] * v[2]).sum::<f64>() / nodes.len() as f64).sqrt();
    let nodes = nodes.iter().map(|v| v.map(|c| (c / rms) as f32)).collect();
    let grid = GridData::new([N, 1, N], FRAMES, nodes)?;
    std::fs::write(&out, grid.to_png(RANGE)?).map_err(|e| format!("{out}: {e}"))?;
    println!("{out}: {N}×{N} nodes, {FRAMES} frames, rms 1 m/s, ±{RANGE} m/s");
    Ok(())
}

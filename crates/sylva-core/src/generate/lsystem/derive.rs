//! Parallel derivation of the L-system string.
//!
//! Each step rewrites the string in chunks on rayon's pool. A module's production choice
//! depends only on (seed, step, module index), so chunking and thread count never change
//! the result. Sizes are counted while rewriting; a step that would pass
//! [`Limits::max_modules`], [`Limits::max_parameters`] or [`Limits::max_segments`] stops
//! before allocating past it.

use super::{Grammar, LSystemError, LSystemOptions};
use crate::limits::LimitExceeded;
use crate::rng::{child_key, hash_unit, mix64};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// One module of the string: a symbol and its parameters `params[off .. off + n]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Module {
    /// Symbol (ASCII).
    pub sym: u8,
    /// Number of parameters.
    pub n: u8,
    /// Offset of the parameters.
    pub off: u32,
}

/// One piece of a derived string: modules and their flat parameter array.
#[derive(Debug, Clone, Default)]
pub struct Piece {
    /// Modules in order.
    pub modules: Vec<Module>,
    /// Parameters of this piece's modules.
    pub params: Vec<f64>,
}

/// A derived string, stored as the pieces the parallel rewrite produced (joining them would
/// copy the whole string every step). Two strings are equal when their modules and
/// parameters are, however they are split into pieces.
#[derive(Debug, Clone, Default)]
pub struct LString {
    /// Pieces in order.
    pub pieces: Vec<Piece>,
}

impl PartialEq for LString {
    fn eq(&self, other: &Self) -> bool {
        self.len() == other.len() && self.iter().zip(other.iter()).all(|(a, b)| a.0 == b.0 && a.1 == b.1)
    }
}

impl LString {
    /// Number of modules.
    pub fn len(&self) -> usize {
        self.pieces.iter().map(|p| p.modules.len()).sum()
    }

    /// True when the string is empty.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Modules in order, as (symbol, parameters).
    pub fn iter(&self) -> impl Iterator<Item = (u8, &[f64])> + '_ {
        self.pieces.iter().flat_map(|p| {
            p.modules.iter().map(move |m| (m.sym, &p.params[m.off as usize..m.off as usize + m.n as usize]))
        })
    }

    /// Number of modules with symbol `sym` (`F`: segments the turtle will draw, at most).
    pub fn count(&self, sym: u8) -> usize {
        self.pieces.iter().map(|p| p.modules.iter().filter(|m| m.sym == sym).count()).sum()
    }

    /// The string as text, e.g. `F(1)[+(45)A(0.5)]`.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        for (sym, a) in self.iter() {
            s.push(sym as char);
            if !a.is_empty() {
                s.push('(');
                for (k, v) in a.iter().enumerate() {
                    if k > 0 {
                        s.push(',');
                    }
                    s.push_str(&format!("{v}"));
                }
                s.push(')');
            }
        }
        s
    }
}

struct Chunk {
    modules: Vec<Module>,
    params: Vec<f64>,
    segments: usize,
}

pub(super) fn derive(g: &Grammar, opts: &LSystemOptions) -> Result<LString, LSystemError> {
    let limits = &opts.limits;
    let iterations = opts.iterations.unwrap_or(g.iterations);
    let limit_err = |limit: &'static str, value: usize| LSystemError::Limit {
        file: g.file.clone(),
        source: LimitExceeded { limit, value },
    };
    if iterations > limits.max_iterations {
        return Err(limit_err("max_iterations", limits.max_iterations as usize));
    }
    let mut by_sym: Vec<Vec<usize>> = vec![Vec::new(); 256];
    for (i, p) in g.productions.iter().enumerate() {
        by_sym[p.pred as usize].push(i);
    }
    // A (symbol, arity) group is stochastic when any of its productions has a probability.
    let stochastic = |sym: u8, n: usize| {
        by_sym[sym as usize].iter().any(|&i| g.productions[i].arity == n && g.productions[i].prob.is_some())
    };

    let mut axiom = Piece::default();
    for (s, args) in &g.axiom {
        axiom.modules.push(Module { sym: *s, n: args.len() as u8, off: axiom.params.len() as u32 });
        axiom.params.extend_from_slice(args);
    }
    let mut cur = LString { pieces: vec![axiom] };
    if g.productions.is_empty() {
        return Ok(cur);
    }
    let mut stoch_table = vec![[false; 256]; 256];
    for (sym, row) in stoch_table.iter_mut().enumerate() {
        for (n, v) in row.iter_mut().enumerate() {
            *v = stochastic(sym as u8, n);
        }
    }
    let base_key = mix64(opts.seed ^ 0x4C53_5953_5445_4D00);

    let mut growth = (2.0f64, 2.0f64);
    for step in 0..iterations {
        let step_key = child_key(base_key, step as u64);
        let n = cur.len();
        let threads = rayon::current_num_threads().max(1);
        let chunk = (n / (threads * 4)).clamp(4096, 1 << 20);
        // Work items: (piece, first module, end module, global index of the first module).
        let mut work = Vec::new();
        let mut base = 0usize;
        for (pi, p) in cur.pieces.iter().enumerate() {
            let len = p.modules.len();
            let mut lo = 0;
            while lo < len {
                let hi = (lo + chunk).min(len);
                work.push((pi, lo, hi, base + lo));
                lo = hi;
            }
            base += len;
        }
        let total_modules = AtomicUsize::new(0);
        let total_params = AtomicUsize::new(0);
        let total_segments = AtomicUsize::new(0);
        let stop = AtomicBool::new(false);
        let cur_ref = &cur;
        // Growth of the previous step sizes each chunk's output up front.
        let growth_m = growth.0;
        let growth_p = growth.1;
        let chunks: Vec<Result<Chunk, Option<LSystemError>>> = work
            .par_iter()
            .map(|&(pi, lo, hi, global)| {
                let piece = &cur_ref.pieces[pi];
                let est = ((hi - lo) as f64 * growth_m * 1.05) as usize + 16;
                let est_p = ((hi - lo) as f64 * growth_p * 1.05) as usize + 16;
                let mut out = Chunk {
                    modules: Vec::with_capacity(est.min(limits.max_modules)),
                    params: Vec::with_capacity(est_p.min(limits.max_parameters)),
                    segments: 0,
                };
                let (mut flushed_m, mut flushed_p, mut flushed_s) = (0usize, 0usize, 0usize);
                let mut matches: Vec<(usize, f64)> = Vec::new();
                for j in lo..hi {
                    let m = piece.modules[j];
                    let args = &piece.params[m.off as usize..m.off as usize + m.n as usize];
                    matches.clear();
                    let sto = stoch_table[m.sym as usize][m.n as usize];
                    for &pi in &by_sym[m.sym as usize] {
                        let p = &g.productions[pi];
                        if p.arity != m.n as usize {
                            continue;
                        }
                        if let Some(c) = &p.cond {
                            let v = c.eval(args);
                            if v == 0.0 || v.is_nan() {
                                continue;
                            }
                        }
                        matches.push((pi, p.prob.unwrap_or(1.0)));
                        if !sto {
                            break;
                        }
                    }
                    let chosen = match matches.len() {
                        0 => None,
                        1 => Some(matches[0].0),
                        _ => {
                            let total: f64 = matches.iter().map(|m| m.1).sum();
                            let mut r = hash_unit(child_key(step_key, (global + j - lo) as u64)) * total;
                            let mut pick = matches[matches.len() - 1].0;
                            for &(pi, w) in &matches {
                                if r < w {
                                    pick = pi;
                                    break;
                                }
                                r -= w;
                            }
                            Some(pick)
                        }
                    };
                    match chosen {
                        None => {
                            out.modules.push(Module { sym: m.sym, n: m.n, off: out.params.len() as u32 });
                            out.params.extend_from_slice(args);
                            out.segments += (m.sym == b'F') as usize;
                        }
                        Some(pi) => {
                            for (s, exprs) in &g.productions[pi].succ {
                                out.modules.push(Module {
                                    sym: *s,
                                    n: exprs.len() as u8,
                                    off: out.params.len() as u32,
                                });
                                for e in exprs {
                                    out.params.push(e.eval(args));
                                }
                                out.segments += (*s == b'F') as usize;
                            }
                        }
                    }
                    if out.modules.len() - flushed_m >= 4096 || j + 1 == hi {
                        let tm = total_modules.fetch_add(out.modules.len() - flushed_m, Ordering::Relaxed)
                            + out.modules.len()
                            - flushed_m;
                        let tp = total_params.fetch_add(out.params.len() - flushed_p, Ordering::Relaxed)
                            + out.params.len()
                            - flushed_p;
                        let ts = total_segments.fetch_add(out.segments - flushed_s, Ordering::Relaxed) + out.segments
                            - flushed_s;
                        flushed_m = out.modules.len();
                        flushed_p = out.params.len();
                        flushed_s = out.segments;
                        if tm > limits.max_modules {
                            stop.store(true, Ordering::Relaxed);
                            return Err(Some(limit_err("max_modules", limits.max_modules)));
                        }
                        if tp > limits.max_parameters || tp > u32::MAX as usize {
                            stop.store(true, Ordering::Relaxed);
                            return Err(Some(limit_err("max_parameters", limits.max_parameters)));
                        }
                        if ts > limits.max_segments {
                            stop.store(true, Ordering::Relaxed);
                            return Err(Some(limit_err("max_segments", limits.max_segments)));
                        }
                        if stop.load(Ordering::Relaxed) {
                            return Err(None);
                        }
                    }
                }
                Ok(out)
            })
            .collect();
        // Report the first error in string order (deterministic), preferring a real limit.
        let mut parts = Vec::with_capacity(chunks.len());
        let mut stopped = false;
        for c in chunks {
            match c {
                Ok(c) => parts.push(c),
                Err(Some(e)) => return Err(e),
                Err(None) => stopped = true,
            }
        }
        if stopped {
            return Err(limit_err("max_modules", limits.max_modules));
        }
        let nm: usize = parts.iter().map(|c| c.modules.len()).sum();
        let np: usize = parts.iter().map(|c| c.params.len()).sum();
        growth = (nm as f64 / n.max(1) as f64, np as f64 / n.max(1) as f64);
        cur = LString { pieces: parts.into_iter().map(|c| Piece { modules: c.modules, params: c.params }).collect() };
    }
    Ok(cur)
}

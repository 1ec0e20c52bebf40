//! One CPU driver for every method: picks the method by name, keeps its state, and turns
//! (time, time step) into the pose seam's buffers. What exporters and tools that bake
//! animation use, so they need not know each method's state type.

use super::akagi::{Akagi, AkagiParams, AkagiState};
use super::hsm::{Hsm, HsmError, HsmParams, HsmState};
use super::skjermo::{Skjermo, SkjermoParams, SkjermoState};
use super::zioma::{Zioma, ZiomaParams};
use crate::mesh::pose_buffers;
use crate::model::Tree;
use crate::scene::MethodName;
use crate::wind::raw::{RawField, RawWave};

/// A method with its state, on the CPU.
#[derive(Debug)]
pub enum CpuAnimator {
    /// Zioma: stateless, the pose at `t` alone.
    Zioma(Box<Zioma>),
    /// Akagi: damped angular springs.
    Akagi(Box<Akagi>, Box<AkagiState>),
    /// Skjermo: Bézier bending.
    Skjermo(Box<Skjermo>, Box<SkjermoState>),
    /// Song et al.: hierarchical shape matching.
    Hsm(Box<Hsm>, Box<HsmState>),
}

impl CpuAnimator {
    /// The method `method` with its default parameters, at rest. `seed` seeds Zioma's
    /// per-branch phases (the other methods have no randomness of their own).
    pub fn new(tree: &Tree, method: MethodName, seed: u64) -> Result<Self, HsmError> {
        Ok(match method {
            MethodName::Zioma => Self::Zioma(Box::new(Zioma::new(tree, ZiomaParams { seed, ..Default::default() }))),
            MethodName::Akagi => {
                let m = Akagi::new(tree, AkagiParams::default());
                let s = m.rest_state(tree);
                Self::Akagi(Box::new(m), Box::new(s))
            }
            MethodName::Skjermo => {
                let m = Skjermo::new(tree, SkjermoParams::default());
                let s = m.rest_state(tree);
                Self::Skjermo(Box::new(m), Box::new(s))
            }
            MethodName::Hsm => {
                let m = Hsm::new(tree, HsmParams::default())?;
                let s = m.rest_state();
                Self::Hsm(Box::new(m), Box::new(s))
            }
        })
    }

    /// True for methods whose pose depends on earlier steps.
    pub fn is_stateful(&self) -> bool {
        !matches!(self, Self::Zioma(_))
    }

    /// Advances `steps` steps of `dt` seconds (stateful methods; Zioma ignores them) and
    /// returns the pose at time `t` as the seam's buffers: joint positions (w = 0) and
    /// accumulated rotations `D`.
    pub fn advance(
        &mut self,
        tree: &Tree,
        fields: &[RawField],
        waves: &[RawWave],
        t: f32,
        dt: f32,
        steps: usize,
    ) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
        let pose = match self {
            Self::Zioma(m) => m.pose_packed(tree, fields, waves, t),
            Self::Akagi(m, s) => {
                for _ in 0..steps {
                    m.step(tree, fields, waves, s, dt);
                }
                return pose_buffers(tree, &s.pose);
            }
            Self::Skjermo(m, s) => {
                for _ in 0..steps {
                    m.step(tree, fields, waves, s, dt);
                }
                return pose_buffers(tree, &s.pose);
            }
            Self::Hsm(m, s) => {
                for _ in 0..steps {
                    m.step(fields, waves, s, dt);
                }
                m.pose(tree, s)
            }
        };
        pose_buffers(tree, &pose)
    }
}

//! Tree generators: both produce a [`TreeBuilder`](crate::model::TreeBuilder) that the model
//! turns into a validated [`Tree`](crate::Tree).
//!
//! * [`lsystem`]: parametric, stochastic L-systems with a 3-D turtle (Song §3; ABOP ch. 1–2).
//! * [`weber_penn`]: Weber & Penn (1995) parametric trees (Skjermo §2.1).

pub mod lsystem;
pub mod weber_penn;

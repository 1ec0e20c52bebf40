//! The method registry: a method's name → its CPU and GPU constructors. Scene files name
//! methods; the world looks them up here. The built-in methods are [`BUILTIN`]; an
//! application registers its own ([`MethodRegistry::register`]) and uses them in scenes
//! like the built-in ones.

use crate::RuntimeError;
use std::sync::Arc;
use sylva_core::Tree;
use sylva_core::methods::{Animator, MethodError, MethodOptions, akagi, hsm, skjermo, zioma};
use sylva_gpu::methods::GpuConstructor;

/// A method's CPU constructor.
pub type CpuConstructor = fn(Arc<Tree>, &MethodOptions) -> Result<Box<dyn Animator>, MethodError>;

/// One animation method.
#[derive(Debug, Clone, Copy)]
pub struct MethodEntry {
    /// The name scene files use (lower case).
    pub name: &'static str,
    /// One line for users: the paper and the mechanism.
    pub summary: &'static str,
    /// True when the method poses every placed instance on its own (stateless methods:
    /// each copy samples the wind where it stands); false when copies share simulations
    /// (a scene tree's `phase_groups`).
    pub per_instance: bool,
    /// The CPU constructor.
    pub cpu: CpuConstructor,
    /// The GPU constructor, when the method has a GPU twin.
    pub gpu: Option<GpuConstructor>,
}

/// The built-in methods.
pub const BUILTIN: [MethodEntry; 4] = [
    MethodEntry {
        name: "zioma",
        summary: "Zioma (GPU Gems 3 ch. 6): procedural, stateless; trunk noise bands and per-branch sway",
        per_instance: true,
        cpu: zioma::animator,
        gpu: Some(sylva_gpu::methods::zioma::animator),
    },
    MethodEntry {
        name: "akagi",
        summary: "Akagi & Kitajima §2.5: wind forces propagated to the root, damped angular springs",
        per_instance: false,
        cpu: akagi::animator,
        gpu: Some(sylva_gpu::methods::akagi::animator),
    },
    MethodEntry {
        name: "skjermo",
        summary: "Skjermo §4: one Bézier per stem, re-attached and bent by the wind each step",
        per_instance: false,
        cpu: skjermo::animator,
        gpu: Some(sylva_gpu::methods::skjermo::animator),
    },
    MethodEntry {
        name: "hsm",
        summary: "Song et al.: hierarchical shape matching, every segment and leaf a cluster of particles",
        per_instance: false,
        cpu: hsm::animator,
        gpu: Some(sylva_gpu::methods::hsm::animator),
    },
];

/// The methods a world can build, by name.
#[derive(Debug, Clone)]
pub struct MethodRegistry {
    entries: Vec<MethodEntry>,
}

impl Default for MethodRegistry {
    fn default() -> Self {
        Self::builtin()
    }
}

impl MethodRegistry {
    /// The built-in methods.
    pub fn builtin() -> Self {
        Self { entries: BUILTIN.to_vec() }
    }

    /// No methods at all.
    pub fn empty() -> Self {
        Self { entries: Vec::new() }
    }

    /// Adds a method; its name must be new and a lower-case identifier.
    pub fn register(&mut self, entry: MethodEntry) -> Result<(), RuntimeError> {
        let ok = !entry.name.is_empty()
            && entry.name.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
            && entry.name.starts_with(|c: char| c.is_ascii_lowercase());
        if !ok {
            return Err(RuntimeError::Registry(format!(
                "method name `{}`: expected a lower-case identifier (a–z, 0–9, _)",
                entry.name
            )));
        }
        if self.get(entry.name).is_some() {
            return Err(RuntimeError::Registry(format!("a method named `{}` is already registered", entry.name)));
        }
        self.entries.push(entry);
        Ok(())
    }

    /// The method `name`.
    pub fn get(&self, name: &str) -> Option<&MethodEntry> {
        self.entries.iter().find(|e| e.name == name)
    }

    /// The method `name`, or an error listing the known ones.
    pub fn entry(&self, name: &str) -> Result<&MethodEntry, MethodError> {
        self.get(name).ok_or_else(|| MethodError::Unknown { name: name.to_string(), known: self.names().join(", ") })
    }

    /// Every method's name, in registration order.
    pub fn names(&self) -> Vec<&'static str> {
        self.entries.iter().map(|e| e.name).collect()
    }

    /// Every method.
    pub fn entries(&self) -> &[MethodEntry] {
        &self.entries
    }

    /// Builds `name` on the CPU.
    pub fn cpu(&self, name: &str, tree: Arc<Tree>, options: &MethodOptions) -> Result<Box<dyn Animator>, MethodError> {
        (self.entry(name)?.cpu)(tree, options)
    }
}

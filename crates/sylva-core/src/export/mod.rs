//! Exporters (CPU). Every file is written atomically: completely or not at all.

pub mod obj;

pub use obj::{ObjOptions, write_obj};

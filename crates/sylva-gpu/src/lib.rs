pub use sylva_core;

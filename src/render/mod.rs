//! The CPU renderer: pictures of a scene drawn without a GPU.
//!
//! So far it has [`lines`]: one-pixel lines (silhouettes, intersection curves) broadened to
//! an exact width. The parts that project and shade surfaces and compose the picture come
//! later and build on it.

pub mod lines;

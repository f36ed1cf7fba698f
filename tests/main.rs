//! Integration tests, one module per stage.

mod adaptive;
mod animate;
mod architecture;
mod certified;
mod certify;
mod cli;
mod common;
mod curves_export;
mod export;
mod figure;
mod fuzz;
mod fuzz_build;
mod gallery;
mod halo;
mod halo_export;
mod house;
mod intersect;
mod lines;
mod motion;
mod own;
mod progress;
mod proven;
mod readme;
mod refine;
mod refused;
mod render;
mod sample;
mod scene;
mod stipple;
mod surfaces;
mod tetmeshes;
mod view;
#[cfg(feature = "viewer")]
mod viewer;
mod viewsearch;

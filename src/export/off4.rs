//! 4D meshes as Geomview `4OFF` text, which [`crate::import::read_mesh4`] reads back bit for
//! bit: a build's surfaces before the view (`outputs.off4`), for other 4D viewers or for a
//! scene of a `mesh` surface.

use glam::DVec4;
use std::fmt::Write;

/// The mesh as ASCII `4OFF` text, `name` in its comment line, every coordinate written so
/// that it reads back to the same f64 (Rust's shortest round-trip form). Non-finite
/// coordinates are written as they are (`NaN`, `inf`), which the reader refuses.
pub fn to_4off(positions: &[DVec4], triangles: &[[u32; 3]], name: &str) -> String {
    let mut out = String::with_capacity(64 + 40 * positions.len() + 16 * triangles.len());
    out += "4OFF\n";
    // A name is one line (the scene's names are checked to be printable), but a caller's
    // own may not be.
    let name: String = name.chars().filter(|c| !c.is_control()).collect();
    let _ = writeln!(out, "# {name}: a triangle mesh in R^4, x y z w per vertex");
    let _ = writeln!(out, "{} {} 0", positions.len(), triangles.len());
    for p in positions {
        // Debug is Display's shortest round-trip digits, with an exponent for tiny and huge
        // numbers (1e-300, not 300 zeros).
        let _ = writeln!(out, "{:?} {:?} {:?} {:?}", p.x, p.y, p.z, p.w);
    }
    for [a, b, c] in triangles {
        let _ = writeln!(out, "3 {a} {b} {c}");
    }
    out
}

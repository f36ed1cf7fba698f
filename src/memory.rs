//! The memory a command may use, and the checks that stages make before they allocate what
//! grows with their input: the stages from the halos on, by their triangles
//! ([`BUILD_BYTES_PER_TRIANGLE`]), and the renderer, by its pixels and, in `slices` mode,
//! its per-sample hits. The intersection stage streams its candidate pairs, so they add
//! nothing that grows with their number.
//!
//! The limit is `HALO4D_MAX_MEMORY` (gigabytes) when set, else three quarters of this
//! machine's memory (`MemTotal` of `/proc/meminfo`), else 16 GB where that cannot be read.

use crate::limits::MAX_MEMORY;

/// Bytes in a gigabyte, as the limit and the messages count them.
pub const GB: f64 = 1e9;

/// Peak resident bytes per triangle of a build from the halos on (two layers of
/// tetrahedra, the checker's incidence, the curves, the verification's index, the `.glb`'s
/// chunks while the files stream), with a margin: measured 830 bytes at 1,000,000 triangles,
/// 750 at 4,000,000 and 730 at 10,000,000 (`report.json`'s `memory.peak_gb` of `cargo bench
/// --bench scale`, the flat torus with glb, vtk, ply and report).
pub const BUILD_BYTES_PER_TRIANGLE: f64 = 1100.0;

/// The limit in bytes, and where it comes from (for messages).
pub fn limit() -> Result<(f64, &'static str), String> {
    if let Ok(text) = std::env::var("HALO4D_MAX_MEMORY") {
        let gb = text.trim().parse::<f64>().map_err(|_| {
            format!(
                "HALO4D_MAX_MEMORY: {text:?} is not a number; give {}",
                MAX_MEMORY.words()
            )
        })?;
        MAX_MEMORY
            .check("HALO4D_MAX_MEMORY", gb)
            .map_err(|e| e.to_string())?;
        return Ok((gb * GB, "HALO4D_MAX_MEMORY"));
    }
    let total = std::fs::read_to_string("/proc/meminfo").ok().and_then(|m| {
        let line = m.lines().find(|l| l.starts_with("MemTotal:"))?;
        let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
        Some(kb * 1e3)
    });
    Ok(match total {
        Some(bytes) => (
            0.75 * bytes,
            "three quarters of this machine's memory; set HALO4D_MAX_MEMORY (GB) to change it",
        ),
        None => (
            16.0 * GB,
            "16 GB, this machine's memory being unknown; set HALO4D_MAX_MEMORY (GB) to change it",
        ),
    })
}

/// This process's peak resident memory so far in bytes (`VmHWM` of `/proc/self/status`;
/// `None` where that cannot be read).
pub fn peak_resident() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1e3)
}

//! The memory a command may use, and the checks that stages make before they allocate what
//! grows with their input: a build, by its triangles and the stages it runs
//! ([`build_bytes`]), and the renderer, by its pixels and, in `slices` mode,
//! its per-sample hits. The intersection stage streams its candidate pairs, so they add
//! nothing that grows with their number.
//!
//! The limit is `HALO4D_MAX_MEMORY` (gigabytes) when set, else three quarters of this
//! machine's memory (`MemTotal` of `/proc/meminfo`), else 16 GB where that cannot be read.

use crate::limits::MAX_MEMORY;

/// Bytes in a gigabyte, as the limit and the messages count them.
pub const GB: f64 = 1e9;

/// What every build holds whatever its size (the program, the threads' stacks and the
/// allocator's arenas, the buffers of fixed size): 0.12 to 0.14 GB measured from one run to
/// the next at 100,352 triangles with halos, of which 100,352 x
/// [`BUILD_BYTES_PER_TRIANGLE`] is 0.09 GB.
pub const BASE_BYTES: f64 = 55e6;

/// Peak resident bytes per triangle of a build that makes halos (two layers of
/// tetrahedra, the checker's incidence, the verification's indexes, the `.glb`'s chunks
/// while the files stream), over [`BASE_BYTES`]: the flat torus with glb, vtk, ply and
/// report peaks at 0.12 to 0.15, 0.88, 3.22 and 7.67 GB at 100,352, 1,002,528, 3,998,792
/// and 9,999,392 triangles (`HALO4D_SCALE=100k,1M,4M,10M cargo bench --bench scale`), the
/// default scene at tolerance 1e-5 (1,241,550 triangles) at 1.00 GB: this estimate is
/// high by 0 to 25% (the most at 100,000, whose peak moves by 15% between runs).
pub const BUILD_BYTES_PER_TRIANGLE: f64 = 900.0;

/// The same for a build that makes the curves but no halos: 0.37 GB at 1,002,528
/// triangles.
pub const CURVES_BYTES_PER_TRIANGLE: f64 = 360.0;

/// The same for the sampling and projection alone, adaptive (spade's triangulations, the
/// queue): 0.52 GB at 1,327,286 triangles.
pub const ADAPTIVE_BYTES_PER_TRIANGLE: f64 = 400.0;

/// The same on a uniform grid or from a mesh file: 0.19 GB at 1,002,528 triangles.
pub const SAMPLE_BYTES_PER_TRIANGLE: f64 = 170.0;

/// The estimated peak resident bytes of a build of `triangles` triangles, by its most
/// demanding stage: the halos, else the curves, else the sampling (`adaptive` or not).
/// Measured from outside, it is high by 0 to 25% from 100,000 to 10 million triangles.
pub fn build_bytes(triangles: usize, adaptive: bool, curves: bool, halos: bool) -> f64 {
    let sampling = if adaptive {
        ADAPTIVE_BYTES_PER_TRIANGLE
    } else {
        SAMPLE_BYTES_PER_TRIANGLE
    };
    let per = if halos {
        BUILD_BYTES_PER_TRIANGLE
    } else if curves {
        CURVES_BYTES_PER_TRIANGLE.max(sampling)
    } else {
        sampling
    };
    BASE_BYTES + triangles as f64 * per
}

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
        let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
        Some(kib * 1024.0)
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
    // The kernel's "kB" are KiB, as `/usr/bin/time`'s %M.
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024.0)
}

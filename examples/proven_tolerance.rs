//! The proven tolerance against the audited one, for every catalogue surface: at each
//! relative tolerance, the adaptive sampler aiming at the audit and aiming at the proof,
//! with the triangles each takes, both errors of each mesh (relative to the tolerance), and
//! the time of sampling and of the proof. The figures of `docs/PERFORMANCE.md` § The proven
//! tolerance.
//!
//! ```sh
//! cargo run --release --example proven_tolerance              # at 1e-3
//! cargo run --release --example proven_tolerance -- 1e-3 1e-4
//! ```

use halo4d::sample::{ErrorBound, audit, bounding_diagonal, prove, sample_adaptive_to};
use halo4d::surfaces::Surface;
use std::process::ExitCode;
use std::time::Instant;

fn main() -> ExitCode {
    let mut tolerances = Vec::new();
    for arg in std::env::args().skip(1) {
        match arg.parse::<f64>() {
            Ok(t) if t > 0.0 && t < 1.0 => tolerances.push(t),
            _ => {
                eprintln!("error: `{arg}` is not a relative tolerance in (0, 1), such as 1e-3");
                return ExitCode::FAILURE;
            }
        }
    }
    if tolerances.is_empty() {
        tolerances.push(1e-3);
    }
    println!(
        "| surface | tolerance | aim | triangles | audited / tol | proven / tol | sample s | proof s |"
    );
    println!("| --- | ---: | --- | ---: | ---: | ---: | ---: | ---: |");
    for surface in Surface::catalogue() {
        let diagonal = bounding_diagonal(&surface);
        for &relative in &tolerances {
            let tolerance = relative * diagonal;
            for aim in [ErrorBound::Audited, ErrorBound::Proven] {
                let start = Instant::now();
                let out = sample_adaptive_to(&surface, tolerance, aim, 4_000_000);
                let sample_s = start.elapsed().as_secs_f64();
                let audited = audit(&surface, &out.mesh).max_error;
                let start = Instant::now();
                let proof = prove(&surface, &out.mesh);
                let proof_s = start.elapsed().as_secs_f64();
                let proven = match proof.max_error {
                    Some(p) => format!("{:.3}", p / tolerance),
                    None => format!("none ({} unproven)", proof.unproven),
                };
                println!(
                    "| {} | {relative:e} | {}{} | {} | {:.3} | {proven} | {sample_s:.3} | {proof_s:.3} |",
                    surface.type_name(),
                    if aim == ErrorBound::Proven {
                        "proven"
                    } else {
                        "audited"
                    },
                    if out.complete { "" } else { " (budget)" },
                    out.mesh.triangles.len(),
                    audited / tolerance,
                );
            }
        }
    }
    ExitCode::SUCCESS
}

//! Certifies the double curves of a scene's surfaces in its view and prints the
//! certificate: `cargo run --release --example certify_scene -- fixtures/scenes/flat-torus.json`.

use halo4d::Scene;
use halo4d::intersect::certified::certify;
use std::path::Path;

fn main() {
    for arg in std::env::args().skip(1) {
        let scene = match Scene::load(Path::new(&arg)) {
            Ok(s) => s,
            Err(e) => {
                eprintln!("{arg}: {e}");
                std::process::exit(2);
            }
        };
        let surfaces: Vec<_> = scene
            .surfaces
            .iter()
            .map(|s| s.surface.parametric())
            .collect();
        let c = certify(&surfaces, &scene.view);
        println!("{arg}: {}", serde_json::to_string(&c).unwrap());
        for (k, comp) in c.components.iter().enumerate() {
            println!(
                "  component {k}: {:?}, {} arcs, width {:.2e}",
                comp.kind, comp.arcs, comp.width
            );
        }
        for r in &c.regions {
            println!("  undecided: {r}");
        }
    }
}

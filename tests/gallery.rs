//! Paper 000's figures: the gallery command, the 4D lighting and the outlined halos.

use crate::common::{fixture, halo4d, scenes_in};
use halo4d::Scene;

/// The figures' scene files copied into `dir` with pictures `side` pixels high (and wide,
/// for each eye).
fn small_figures(dir: &std::path::Path, side: u32) {
    for file in scenes_in("figures") {
        let mut json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
        let render = json
            .as_object_mut()
            .unwrap()
            .entry("render")
            .or_insert_with(|| serde_json::json!({}));
        render["width"] = side.into();
        render["height"] = side.into();
        std::fs::write(
            dir.join(file.file_name().unwrap()),
            serde_json::to_string(&json).unwrap(),
        )
        .unwrap();
    }
}

#[test]
fn the_gallery_builds_every_figure_of_paper_000_verified_with_an_index_and_a_sheet() {
    let names: Vec<String> = scenes_in("figures")
        .iter()
        .map(|f| Scene::load(f).unwrap().name)
        .collect();
    // Every figure of paper 000 that shows a surface.
    for figure in [
        "fig1a", "fig1b", "fig1c", "fig5a", "fig5b", "fig5c", "fig5d", "fig6a", "fig6b", "fig7",
        "fig8",
    ] {
        assert!(
            names.iter().any(|n| n.starts_with(&format!("{figure}-"))),
            "no scene for paper 000's {figure} in fixtures/figures: {names:?}"
        );
    }
    let dir = tempfile::tempdir().unwrap();
    let figures = dir.path().join("figures");
    std::fs::create_dir(&figures).unwrap();
    small_figures(&figures, 160);
    let out = halo4d(
        &["gallery", "figures", "--out", "gallery", "-q"],
        dir.path(),
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let gallery = dir.path().join("gallery");
    let index = std::fs::read_to_string(gallery.join("index.html")).unwrap();
    let mut width = 0;
    for name in &names {
        let picture = format!("{name}/{name}.png");
        assert!(index.contains(&format!("src=\"{picture}\"")), "{name}");
        let png = image::open(gallery.join(&picture)).unwrap().to_rgb8();
        // Not blank: the surfaces cover a tenth of the picture.
        let covered = png.pixels().filter(|p| p.0 != [255; 3]).count();
        assert!(
            covered * 10 > (png.width() * png.height()) as usize,
            "{name}: {covered} pixels drawn"
        );
        let report: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(gallery.join(name).join("report.json")).unwrap(),
        )
        .unwrap();
        assert_eq!(report["verified"], true, "{name}");
        assert!(stderr.contains(name), "{name} is not listed: {stderr}");
        width += png.width() * halo4d::gallery::SHEET_ROW / png.height();
    }
    assert!(!index.contains("NOT verified"));
    // The sheet holds every picture at its row height, in rows up to its width.
    let sheet = image::open(gallery.join("gallery.png")).unwrap().to_rgb8();
    assert_eq!(sheet.width(), halo4d::gallery::SHEET_WIDTH);
    let rows = sheet.height() / halo4d::gallery::SHEET_ROW;
    assert_eq!(sheet.height() % halo4d::gallery::SHEET_ROW, 0);
    assert!(rows * halo4d::gallery::SHEET_WIDTH >= width);
    assert!((rows - 1) * halo4d::gallery::SHEET_WIDTH < width);
}

#[test]
fn a_gallery_of_no_scene_or_of_two_scenes_of_one_name_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("empty")).unwrap();
    let out = halo4d(&["gallery", "empty", "-q"], dir.path());
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("empty: no scene file (*.json)"), "{stderr}");
    let out = halo4d(&["gallery", "missing", "-q"], dir.path());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("missing: cannot read the folder of figures"),
        "{stderr}"
    );
    let twins = dir.path().join("twins");
    std::fs::create_dir(&twins).unwrap();
    let scene = std::fs::read_to_string(fixture("figures/fig1b-patches-no-halos.json")).unwrap();
    for name in ["a.json", "b.json"] {
        std::fs::write(twins.join(name), &scene).unwrap();
    }
    let out = halo4d(&["gallery", "twins", "-q"], dir.path());
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("a.json and twins/b.json both name their scene `fig1b-patches-no-halos`"),
        "{stderr}"
    );
    assert!(!dir.path().join("exports").exists(), "nothing is built");
}

/// The picture of `scene` at `side` x `side` pixels per eye.
fn picture(mut scene: Scene, side: u32) -> image::RgbImage {
    (scene.render.width, scene.render.height) = (side, side);
    let built = crate::common::built(&scene).unwrap();
    let p = built
        .render(&scene.halo, &scene.render, &scene.camera)
        .unwrap();
    image::RgbImage::from_raw(p.width, p.height, p.rgb).unwrap()
}

#[test]
fn figure_8_outlines_the_halos_in_its_own_colour() {
    let scene = Scene::load(&fixture("figures/fig8-twist-spun-trefoil-outlined.json")).unwrap();
    let green = |img: &image::RgbImage| {
        img.pixels()
            .filter(|p| {
                let [r, g, b] = p.0.map(i32::from);
                g > r + 60 && g > b + 30
            })
            .count()
    };
    let outlined = green(&picture(scene.clone(), 256));
    let mut plain = scene;
    plain.render.broken_edge_colour = None;
    let ink = green(&picture(plain, 256));
    assert!(outlined > 300, "{outlined} green pixels");
    assert!(ink * 20 < outlined, "{ink} green pixels without the colour");
}

#[test]
fn four_d_lighting_shades_the_sheets_by_how_they_lean_in_w() {
    let scene = Scene::load(&fixture("figures/fig5c-spun-trefoil-4d-lit.json")).unwrap();
    assert_eq!(scene.render.lighting, halo4d::render::Lighting::FourD);
    let four = picture(scene.clone(), 192);
    let mut three = scene;
    three.render.lighting = halo4d::render::Lighting::ThreeD;
    let three = picture(three, 192);
    // The same surfaces in the same places, shaded otherwise.
    let drawn = |img: &image::RgbImage| img.pixels().map(|p| p.0 != [255; 3]).collect::<Vec<_>>();
    assert_eq!(drawn(&four), drawn(&three));
    let differ = four
        .pixels()
        .zip(three.pixels())
        .filter(|(a, b)| (0..3).any(|k| a.0[k].abs_diff(b.0[k]) > 8))
        .count();
    let covered = drawn(&four).iter().filter(|&&d| d).count();
    assert!(
        differ * 5 > covered,
        "{differ} of {covered} covered pixels shaded otherwise"
    );
}

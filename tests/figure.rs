//! The picture in the `.glb`, for programs that know nothing of halo4d: the camera node is
//! the picture's camera (the same pixels for the same points), the halos are in the second
//! glTF scene only, COLOR_0 is the picture's colour map of w; `<name>.html` holds the `.glb`
//! whole.

use base64::Engine;
use glam::{DQuat, DVec3};
use halo4d::Scene;
use halo4d::internals::colormap;
use serde_json::Value;

/// The default scene with a small picture, its page asked for.
fn scene() -> Scene {
    let mut scene = Scene::default_scene();
    (
        scene.render.width,
        scene.render.height,
        scene.render.samples,
    ) = (160, 120, 1);
    scene.outputs.html = true;
    scene
}

/// The JSON chunk of a `.glb`.
fn json_of(glb: &[u8]) -> Value {
    let len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    serde_json::from_slice(&glb[20..20 + len]).unwrap()
}

/// The f32 values of accessor `i` (tightly packed, as halo4d writes them).
fn floats(glb: &[u8], json: &Value, i: u64) -> Vec<f32> {
    let len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let bin = &glb[20 + len + 8..];
    let a = &json["accessors"][i as usize];
    let view = &json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
    let start = view["byteOffset"].as_u64().unwrap_or(0) as usize;
    let width = match a["type"].as_str().unwrap() {
        "SCALAR" => 1,
        "VEC3" => 3,
        other => panic!("type {other}"),
    };
    let n = a["count"].as_u64().unwrap() as usize * width;
    bin[start..start + 4 * n]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

/// halo4d's frame to glTF's (y up): (x, z, -y).
fn to_gltf(p: DVec3) -> DVec3 {
    DVec3::new(p.x, p.z, -p.y)
}

#[test]
fn the_glb_shows_the_picture_through_its_camera_with_the_halos_hidden() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene();
    let built = crate::common::built(&scene).unwrap();
    halo4d::write(&scene, &built, dir.path()).unwrap();
    let name = &scene.name;
    let glb = std::fs::read(dir.path().join(format!("{name}.glb"))).unwrap();
    let json = json_of(&glb);
    let report: Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("report.json")).unwrap()).unwrap();

    // Two scenes: the picture's (the default) and the halos'.
    let scenes = json["scenes"].as_array().unwrap();
    assert_eq!(scenes.len(), 2);
    assert_eq!(json["scene"], 0);
    assert_eq!(scenes[1]["name"], halo4d::export::HALO_SCENE);
    let nodes = json["nodes"].as_array().unwrap();
    let meshes = json["meshes"].as_array().unwrap();
    let in_scene = |k: usize| -> Vec<&Value> {
        scenes[k]["nodes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|i| &nodes[i.as_u64().unwrap() as usize])
            .collect()
    };
    let kind = |node: &Value| -> &str {
        match node["mesh"].as_u64() {
            Some(m) => {
                let extras = &meshes[m as usize]["extras"];
                ["halo", "surface", "curves", "stipples"]
                    .into_iter()
                    .find(|k| extras.get(*k).is_some())
                    .unwrap()
            }
            None if node.get("camera").is_some() => "camera",
            None => "other",
        }
    };
    let picture: Vec<&str> = in_scene(0).into_iter().map(kind).collect();
    assert_eq!(picture, ["surface", "curves", "camera"]);
    let halos: Vec<&str> = in_scene(1).into_iter().map(kind).collect();
    assert_eq!(halos, ["halo"]);
    // halo4d's own reader still finds the halos there, and in a file whose scene leaves out
    // `nodes`, as Blender's exporter writes the halos' emptied scene.
    let read = halo4d::import::read_glb(&glb).unwrap();
    assert_eq!(read.len(), 1);
    let without = crate::common::with_json(&glb, |j| {
        j["scenes"][1].as_object_mut().unwrap().remove("nodes");
    });
    assert_eq!(halo4d::import::read_glb(&without).unwrap().len(), 1);

    // The camera: where the picture's eye is, looking where it looks, and each point of the
    // surface lands on the same pixel through both.
    let camera = &report["picture"];
    let v3 = |v: &Value| {
        DVec3::new(
            v[0].as_f64().unwrap(),
            v[1].as_f64().unwrap(),
            v[2].as_f64().unwrap(),
        )
    };
    let (eye, target, up) = (v3(&camera["eye"]), v3(&camera["target"]), v3(&camera["up"]));
    let fov = camera["fov_deg"].as_f64().unwrap().to_radians();
    let (w, h) = (
        f64::from(scene.render.width),
        f64::from(scene.render.height),
    );
    let node = in_scene(0)
        .into_iter()
        .find(|n| kind(n) == "camera")
        .unwrap();
    let cam = &json["cameras"][node["camera"].as_u64().unwrap() as usize];
    assert_eq!(cam["type"], "perspective");
    let p = &cam["perspective"];
    assert!((p["yfov"].as_f64().unwrap() - fov).abs() < 1e-6);
    assert!((p["aspectRatio"].as_f64().unwrap() - w / h).abs() < 1e-6);
    assert_eq!(cam["extras"]["picture"]["width"], scene.render.width);
    let t = v3(&node["translation"]);
    let r = &node["rotation"];
    let q = DQuat::from_xyzw(
        r[0].as_f64().unwrap(),
        r[1].as_f64().unwrap(),
        r[2].as_f64().unwrap(),
        r[3].as_f64().unwrap(),
    );
    let scale = (target - eye).length();
    assert!((t - to_gltf(eye)).length() < 1e-6 * scale.max(1.0));
    let forward = (target - eye).normalize();
    assert!((q * DVec3::NEG_Z - to_gltf(forward)).length() < 1e-6);
    assert!((q * DVec3::Y - to_gltf(up)).length() < 1e-6);
    let (znear, zfar) = (p["znear"].as_f64().unwrap(), p["zfar"].as_f64().unwrap());
    assert!(0.0 < znear && znear < zfar);

    let right = forward.cross(up);
    let tan = (fov / 2.0).tan();
    let surface = meshes
        .iter()
        .position(|m| m["extras"].get("surface").is_some())
        .unwrap();
    let attributes = &meshes[surface]["primitives"][0]["attributes"];
    let positions = floats(&glb, &json, attributes["POSITION"].as_u64().unwrap());
    let mut checked = 0;
    for v in positions.chunks_exact(3).step_by(97) {
        let x = DVec3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]));
        // Through the picture's camera (halo4d's frame: the glTF point turned back).
        let p = DVec3::new(x.x, -x.z, x.y) - eye;
        let depth = p.dot(forward);
        let picture = [
            (p.dot(right) / depth / (tan * w / h) + 1.0) * 0.5 * w,
            (1.0 - p.dot(up) / depth / tan) * 0.5 * h,
        ];
        // Through the glTF camera: into its frame, then its projection.
        let c = q.inverse() * (x - t);
        let file = [
            (c.x / -c.z / (tan * w / h) + 1.0) * 0.5 * w,
            (1.0 - c.y / -c.z / tan) * 0.5 * h,
        ];
        assert!(
            znear < -c.z && -c.z < zfar,
            "a vertex outside the clipping planes"
        );
        for k in 0..2 {
            assert!(
                (picture[k] - file[k]).abs() < 1e-3,
                "vertex {x}: pixel {picture:?} in the picture, {file:?} through the file's camera"
            );
            assert!(
                (0.0..=[w, h][k]).contains(&file[k]),
                "a vertex outside the picture"
            );
        }
        checked += 1;
    }
    assert!(checked > 20);

    // COLOR_0: the picture's colour map of w over the w of the surfaces' triangle vertices.
    let ws = floats(&glb, &json, attributes["_W"].as_u64().unwrap());
    let colours = floats(&glb, &json, attributes["COLOR_0"].as_u64().unwrap());
    assert_eq!(colours.len(), 3 * ws.len());
    let product = &built.surfaces[0];
    let (w0, w1) = product
        .mesh
        .triangles
        .iter()
        .flatten()
        .map(|&v| product.projected.w[v as usize])
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), w| {
            (a.min(w), b.max(w))
        });
    assert!(w1 > w0);
    for (i, w) in product.projected.w.iter().enumerate().step_by(53) {
        let expected = colormap(scene.render.colormap, (w - w0) / (w1 - w0));
        for k in 0..3 {
            assert!(
                (f64::from(colours[3 * i + k]) - expected[k]).abs() < 1e-6,
                "vertex {i}: COLOR_0 {:?}, the picture's {expected}",
                &colours[3 * i..3 * i + 3]
            );
        }
    }
    let material = &json["materials"][meshes[surface]["primitives"][0]["material"]
        .as_u64()
        .unwrap() as usize];
    assert_eq!(
        material["pbrMetallicRoughness"]["baseColorFactor"],
        serde_json::json!([1.0, 1.0, 1.0, 1.0])
    );

    // The page holds the .glb whole.
    let page = std::fs::read_to_string(dir.path().join(format!("{name}.html"))).unwrap();
    let start = page.find("base64\">").unwrap() + "base64\">".len();
    let end = start + page[start..].find("</script>").unwrap();
    let text: String = page[start..end].split_whitespace().collect();
    let embedded = base64::engine::general_purpose::STANDARD
        .decode(text)
        .unwrap();
    assert_eq!(embedded, glb, "the page's file is not the .glb");
    assert!(
        report["files"]
            .as_array()
            .unwrap()
            .iter()
            .any(|f| f == &format!("{name}.html"))
    );
}

"""Blender's own glTF importer against halo4d's picture: the .glb as a Blender user opens it
(File > Import > glTF 2.0, `bpy.ops.import_scene.gltf`, with its default options and no
add-on), rendered through the camera the file brings, must cover the pixels halo4d's own
picture of the scene covers.

  blender-import.py GLB PICTURE.png OUT_DIR

PICTURE.png is halo4d's picture of the scene the .glb was built from (any size with the
aspect ratio the .glb's camera was made for: `halo4d render --width W --height H`). Blender
(Cycles, CPU, a transparent film) renders the imported scene through the imported camera at
the picture's size. Checked:
  - the file's camera came in (one camera object), and the render looks through it;
  - the halos came in, hidden: each halo mesh is an object that the view layer does not show
    (the file's second glTF scene, whose collection the importer excludes);
  - each surface's material reads its colour attribute (COLOR_0, the picture's colours of w);
  - the silhouettes: a pixel of the picture is covered when it differs from the picture's
    background (render.background, recorded in the .glb) by more than BACKGROUND_STEP in a
    channel, a pixel of the render when its alpha is at least one half; their
    intersection over union (IoU) must be at least MIN_IOU.
Writes OUT_DIR/blender.png (the render on the picture's background), OUT_DIR/halo4d.png (a
copy of the picture), OUT_DIR/side-by-side.png (the picture, the render, and where they
differ: grey both, red the picture only, blue the render only) and OUT_DIR/result.json.
Exit status 0 when every check passes, 1 otherwise.
"""

import json
import shutil
import sys
from pathlib import Path

import numpy as np
from PIL import Image

from silhouette import MIN_IOU, compare, covered

SAMPLES = 32


def glb_json(path):
    data = Path(path).read_bytes()
    if data[:4] != b"glTF":
        sys.exit(f"{path}: not a .glb")
    length = int.from_bytes(data[12:16], "little")
    return json.loads(data[20 : 20 + length])


def main():
    if len(sys.argv) != 4:
        print(__doc__)
        sys.exit(2)
    glb, picture_path, out = Path(sys.argv[1]), Path(sys.argv[2]), Path(sys.argv[3])
    out.mkdir(parents=True, exist_ok=True)
    gltf = glb_json(glb)
    picture = np.asarray(Image.open(picture_path).convert("RGB"))
    height, width = picture.shape[:2]
    scene_settings = gltf["asset"]["extras"]["halo4d"]["scene"]
    background = np.array(scene_settings.get("render", {}).get("background", [1.0, 1.0, 1.0]))
    halo_meshes = {m["name"] for m in gltf["meshes"] if "halo" in (m.get("extras") or {})}
    surface_meshes = {m["name"] for m in gltf["meshes"] if "surface" in (m.get("extras") or {})}

    import bpy  # after the arguments: a usage error needs no Blender

    bpy.ops.wm.read_factory_settings(use_empty=True)
    result = bpy.ops.import_scene.gltf(filepath=str(glb))
    if result != {"FINISHED"}:
        sys.exit(f"import_scene.gltf returned {result}")
    scene = bpy.context.scene
    problems = []

    cameras = [o for o in bpy.data.objects if o.type == "CAMERA"]
    if len(cameras) != 1:
        problems.append(f"expected the file's one camera, Blender has {len(cameras)}")
        print("\n".join(f"FAILED {p}" for p in problems))
        sys.exit(1)
    # The importer makes the camera but does not make it the scene's (in Blender, View >
    # Cameras > Active Camera, or Numpad 0, does).
    scene.camera = cameras[0]

    by_mesh = {o.data.name: o for o in bpy.data.objects if o.type == "MESH"}
    for name in sorted(halo_meshes):
        o = by_mesh.get(name)
        if o is None:
            problems.append(f"halo {name}: not imported")
        elif o.visible_get():
            problems.append(f"halo {name}: imported visible")
    for name in sorted(surface_meshes):
        o = by_mesh.get(name)
        if o is None:
            problems.append(f"surface {name}: not imported")
            continue
        material = o.active_material
        nodes = material.node_tree.nodes if material and material.node_tree else []
        if not any(n.type == "VERTEX_COLOR" and n.outputs[0].is_linked for n in nodes):
            problems.append(f"surface {name}: its material does not read its colour attribute")

    world = bpy.data.worlds.new("light")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (1, 1, 1, 1)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
    scene.world = world
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = SAMPLES
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.use_denoising = False
    scene.render.film_transparent = True
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGBA"
    rendered = out / "blender-rgba.png"
    scene.render.filepath = str(rendered)
    bpy.ops.render.render(write_still=True)

    rgba = np.asarray(Image.open(rendered).convert("RGBA")).astype(np.float64) / 255.0
    alpha = rgba[..., 3:]
    back = np.round(np.clip(background, 0, 1) ** (1 / 2.2) * 255) / 255  # near enough for a backdrop
    on_background = rgba[..., :3] * alpha + back * (1 - alpha)
    blender = (on_background * 255).round().astype(np.uint8)
    Image.fromarray(blender).save(out / "blender.png")
    rendered.unlink()
    if picture_path.resolve() != (out / "halo4d.png").resolve():
        shutil.copyfile(picture_path, out / "halo4d.png")

    # The picture's background as its PNG stores it: the corner pixel, which the fitted
    # camera's margin leaves empty.
    covered_picture = covered(picture)
    covered_blender = alpha[..., 0] >= 0.5
    iou, picture_only, blender_only = compare(picture, covered_picture, blender, covered_blender,
                                              out / "side-by-side.png")

    record = {
        "glb": str(glb),
        "picture": str(picture_path),
        "size": [width, height],
        "iou": float(iou),
        "picture_pixels": int(covered_picture.sum()),
        "blender_pixels": int(covered_blender.sum()),
        "picture_only": picture_only,
        "blender_only": blender_only,
        "min_iou": MIN_IOU,
        "samples": SAMPLES,
        "blender": bpy.app.version_string,
    }
    (out / "result.json").write_text(json.dumps(record, indent=2) + "\n")
    print(
        f"Blender {bpy.app.version_string}'s glTF importer, Cycles {width}x{height} through the file's camera: "
        f"silhouette IoU {iou:.4f} against halo4d's picture ({record['picture_pixels']} pixels covered in the "
        f"picture, {record['blender_pixels']} in the render, {record['picture_only']} only in the picture, "
        f"{record['blender_only']} only in the render); halos imported hidden: {len(halo_meshes)}; "
        f"pictures in {out}"
    )
    if iou < MIN_IOU:
        problems.append(f"silhouette IoU {iou:.4f} < {MIN_IOU}")
    for p in problems:
        print(f"FAILED {p}")
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()

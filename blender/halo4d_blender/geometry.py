"""A halo4d build as Blender data: the surfaces as meshes coloured by w, the curves as poly
splines inked as halo4d's picture inks them, the halos as hidden meshes of their boundary.

Blender's frame is halo4d's (z up), so a surface's vertices are its `positions` as they are:
the `.glb` writes (x, z, -y) and Blender's glTF importer turns it back.
"""

import bpy
import numpy as np

# halo4d's `diverging` colour map (src/render/shade.rs): blue (near in w) through light grey
# to orange (far), linear RGB, evenly spaced.
RAMP = np.array(
    [
        [0.23, 0.30, 0.75],
        [0.55, 0.65, 0.92],
        [0.87, 0.87, 0.87],
        [0.96, 0.66, 0.42],
        [0.85, 0.42, 0.10],
    ]
)
# The picture's curve inks (src/render/overlay.rs): the w scale cut into OVER_BANDS bands,
# a curve drawn in OVER_SHADE times the colour of the band of the sheet that passes over it.
OVER_BANDS = 12
OVER_SHADE = 0.35

SURFACE_MATERIAL = "halo4d w"
HALO_MATERIAL = "halo4d halo"
W_ATTRIBUTE = "w"
COLOUR_ATTRIBUTE = "w_colour"


def ramp(s):
    """The colour map at shares `s` in [0, 1] (0 nearest), (n, 3) linear RGB."""
    x = np.clip(np.nan_to_num(s, nan=0.5), 0.0, 1.0) * (len(RAMP) - 1)
    i = np.minimum(np.floor(x).astype(int), len(RAMP) - 2)
    f = (x - i)[:, None]
    return RAMP[i] * (1.0 - f) + RAMP[i + 1] * f


def w_range(built):
    """The w of the surfaces' triangle vertices, (least, greatest): the picture's scale."""
    lo, hi = np.inf, -np.inf
    for surface in built.surfaces:
        used = surface.w[np.unique(surface.triangles)] if len(surface.triangles) else surface.w
        if len(used):
            lo, hi = min(lo, used.min()), max(hi, used.max())
    return (float(lo), float(hi)) if lo <= hi else (0.0, 1.0)


def scene_diagonal(built):
    """The diagonal of the projected surfaces' bounding box."""
    points = [s.positions for s in built.surfaces if len(s.positions)]
    if not points:
        return 1.0
    points = np.concatenate(points)
    return float(np.linalg.norm(points.max(axis=0) - points.min(axis=0))) or 1.0


def fill_mesh(mesh, vertices, triangles):
    """Replaces `mesh`'s geometry by `vertices` (n, 3) and `triangles` (m, 3), in their order."""
    mesh.clear_geometry()
    vertices = np.ascontiguousarray(vertices, dtype=np.float32)
    triangles = np.ascontiguousarray(triangles, dtype=np.int32)
    mesh.vertices.add(len(vertices))
    mesh.vertices.foreach_set("co", vertices.ravel())
    mesh.loops.add(3 * len(triangles))
    mesh.loops.foreach_set("vertex_index", triangles.ravel())
    mesh.polygons.add(len(triangles))
    mesh.polygons.foreach_set("loop_start", np.arange(0, 3 * len(triangles), 3, dtype=np.int32))
    mesh.update(calc_edges=True)


def fill_surface(mesh, surface, scale):
    """The surface's projected mesh with its w (float attribute `w`) and the colour map
    over the scene's w scale `scale` (colour attribute `w_colour`), shaded smooth."""
    fill_mesh(mesh, surface.positions, surface.triangles)
    w = surface.w
    mesh.attributes.new(W_ATTRIBUTE, "FLOAT", "POINT").data.foreach_set("value", w.astype(np.float32))
    lo, hi = scale
    rgba = np.ones((len(w), 4), dtype=np.float32)
    rgba[:, :3] = ramp((w - lo) / (hi - lo) if hi > lo else np.full(len(w), 0.5))
    colour = mesh.color_attributes.new(COLOUR_ATTRIBUTE, "FLOAT_COLOR", "POINT")
    colour.data.foreach_set("color", rgba.ravel())
    mesh.color_attributes.active_color = colour
    mesh.color_attributes.render_color_index = mesh.color_attributes.active_color_index
    mesh.polygons.foreach_set("use_smooth", np.ones(len(mesh.polygons), dtype=bool))
    mesh.update()


def halo_boundary(vertices, tetrahedra):
    """The boundary of a set of tetrahedra: (vertices, triangles) of the faces only one
    tetrahedron has, wound to face away from it, on the vertices they use."""
    if len(tetrahedra) == 0:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    t = tetrahedra.astype(np.int64)
    faces = np.concatenate([t[:, [1, 2, 3]], t[:, [0, 3, 2]], t[:, [0, 1, 3]], t[:, [0, 2, 1]]])
    opposite = np.concatenate([t[:, 0], t[:, 1], t[:, 2], t[:, 3]])
    key = np.sort(faces, axis=1)
    n = int(t.max()) + 1
    if n < 2**21:
        key = (key[:, 0] * n + key[:, 1]) * n + key[:, 2]
        _, inverse, counts = np.unique(key, return_inverse=True, return_counts=True)
    else:
        _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    once = counts[inverse.ravel()] == 1
    faces, opposite = faces[once], opposite[once]
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    towards = np.einsum("ij,ij->i", np.cross(b - a, c - a), vertices[opposite] - a) > 0
    faces[towards] = faces[towards][:, [0, 2, 1]]
    used, compact = np.unique(faces, return_inverse=True)
    return vertices[used], compact.reshape(-1, 3)


def over_pieces(points, bands, closed):
    """A curve cut where the band of the sheet passing over changes, as halo4d's picture
    cuts it (`over_pieces` in src/render/overlay.rs): (band, points, cyclic) per piece, a
    segment whose ends differ cut at its middle, a closed curve's last piece joined to its
    first where they share a band."""
    if len(points) == 0:
        return []
    if closed and np.all(bands == bands[0]):
        return [(int(bands[0]), points, True)]
    order = list(range(len(points))) + ([0] if closed else [])
    pieces = [(int(bands[0]), [points[0]])]
    for i, j in zip(order[:-1], order[1:], strict=True):
        if bands[j] == pieces[-1][0]:
            pieces[-1][1].append(points[j])
        else:
            middle = (points[i] + points[j]) * 0.5
            pieces[-1][1].append(middle)
            pieces.append((int(bands[j]), [middle, points[j]]))
    if closed and len(pieces) > 1 and pieces[-1][0] == pieces[0][0]:
        band, last = pieces.pop()
        pieces[0] = (band, last[:-1] + pieces[0][1])
    return [(band, np.array(piece), False) for band, piece in pieces]


def ink(band):
    """The linear RGB of band `band`'s curve ink."""
    return ramp(np.array([(band + 0.5) / OVER_BANDS]))[0] * OVER_SHADE


def fill_curves(curve, built, scale):
    """The build's curves as poly splines, each piece in the ink of the band of the w of the
    sheet that passes over it (material slot = band)."""
    curve.splines.clear()
    lo, hi = scale
    span = hi - lo if hi > lo else 1.0
    for c in built.curves:
        points = c.points
        if len(points) < 2:
            continue
        w = c.w
        over = w[np.arange(len(w)), c.over]
        bands = np.minimum((np.clip((over - lo) / span, 0.0, 1.0) * OVER_BANDS).astype(int), OVER_BANDS - 1)
        for band, piece, cyclic in over_pieces(points, bands, c.closed):
            spline = curve.splines.new("POLY")
            spline.points.add(len(piece) - 1)
            co = np.ones((len(piece), 4), dtype=np.float32)
            co[:, :3] = piece
            spline.points.foreach_set("co", co.ravel())
            spline.use_cyclic_u = cyclic
            spline.material_index = band


def material(name, colour, alpha=1.0):
    """The material `name`, made once: a Principled BSDF of `colour`."""
    existing = bpy.data.materials.get(name)
    if existing is not None:
        return existing
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*colour, 1.0)
    bsdf.inputs["Roughness"].default_value = 0.6
    m.diffuse_color = (*colour, alpha)
    if alpha < 1.0:
        bsdf.inputs["Alpha"].default_value = alpha
        if hasattr(m, "surface_render_method"):
            m.surface_render_method = "BLENDED"
        else:
            m.blend_method = "BLEND"
    return m


def surface_material():
    """The surfaces' material: the colour attribute `w_colour` (w through the colour map) as
    the Principled BSDF's base colour."""
    existing = bpy.data.materials.get(SURFACE_MATERIAL)
    if existing is not None:
        return existing
    m = material(SURFACE_MATERIAL, RAMP[2])
    nodes = m.node_tree.nodes
    attribute = nodes.new("ShaderNodeAttribute")
    attribute.attribute_type = "GEOMETRY"
    attribute.attribute_name = COLOUR_ATTRIBUTE
    attribute.location = (-300, 300)
    m.node_tree.links.new(attribute.outputs["Color"], nodes["Principled BSDF"].inputs["Base Color"])
    return m


def ink_materials():
    """The curves' inks, one material per band of w, nearest first."""
    return [material(f"halo4d ink {band:02}", ink(band)) for band in range(OVER_BANDS)]


def halo_material():
    return material(HALO_MATERIAL, (0.8, 0.8, 0.8), alpha=0.25)

// halo4d-view: surfaces, halo depth (grid voxelization and per-frame cuts), curves and the
// transparency composite. Positions are relative to the scene's centre. Halo depth is
// stored normalized: (depth - depth_norm.x) * depth_norm.y, in [0, 1).

struct View {
    clip: mat4x4<f32>,
    // xyz: eye; w: 1 perspective, 0 orthographic.
    eye: vec4<f32>,
    forward: vec4<f32>,
    right: vec4<f32>,
    up: vec4<f32>,
    // rgb: background; a: opacity of transparent surfaces.
    background: vec4<f32>,
    // x: w of the near end of the colour scale; y: 1 / its span.
    w_norm: vec4<f32>,
    // x: depth offset; y: depth scale; z: the grid's sample distance; w: the slabs'.
    depth_norm: vec4<f32>,
    // xyz: the grid's low corner; w: voxel size.
    grid_lo: vec4<f32>,
    // x: depth of the first slab's near side; y: slab thickness; z: slab count; w: far - near.
    slabs: vec4<f32>,
    // x, y, z: voxels; w: texels per row of the grid buffer.
    grid_dims: vec4<u32>,
    // x: flags (1 halos, 2 colour by w, 4 lines test the surfaces' depth, 8 surfaces in the
    // background's colour, for stipples); y: colour stops; z: clip planes (0 to 2);
    // w: samples per pixel along each side.
    options: vec4<u32>,
    // Voxelization of one band of the grid: x: items; y: the band's first z layer.
    band: vec4<u32>,
    // x, y: the frame's size in pixels; z: half the curves' width in pixels; w: a pixel's
    // size at unit depth (perspective) or anywhere (orthographic).
    viewport: vec4<f32>,
    // x, y: the view depths of depth 0 and 1.
    depth_proj: vec4<f32>,
    // x: a stipple's diameter in pixels; y: 1 when stipples take the colour of their w.
    stipple: vec4<f32>,
    stops: array<vec4<f32>, 8>,
    // render.clip: options.z planes (xyz: normal, w: offset, relative to the centre);
    // a point beyond every one is removed.
    cuts: array<vec4<f32>, 2>,
}

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<storage, read> vertices: array<SurfaceVertex>;
@group(0) @binding(2) var grid: texture_3d<u32>;
@group(0) @binding(3) var halo_image: texture_depth_2d;
@group(0) @binding(4) var<storage, read> curve_points: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> halo_vertices: array<HaloVertex>;
@group(0) @binding(6) var<storage, read> tets: array<vec4<u32>>;
// Voxelization: (tetrahedron, z layer); cuts: (tetrahedron, slab).
@group(0) @binding(7) var<storage, read> items: array<vec2<u32>>;
@group(0) @binding(8) var<storage, read_write> grid_buffer: array<atomic<u32>>;
@group(0) @binding(9) var accum_image: texture_2d<f32>;
@group(0) @binding(10) var reveal_image: texture_2d<f32>;
@group(0) @binding(11) var<storage, read> curve_segments: array<vec2<u32>>;
// Interior mesh edges: (a, b, triangle i, triangle j | 1 << 31 where their windings agree).
@group(0) @binding(12) var<storage, read> edges: array<vec4<u32>>;
// Per triangle, its (unnormalized) normal as wound.
@group(0) @binding(13) var<storage, read> face_normals: array<vec4<f32>>;
@group(0) @binding(14) var surface_depth: texture_depth_2d;
@group(0) @binding(15) var samples_image: texture_2d<f32>;
@group(0) @binding(16) var<storage, read> stipples: array<Stipple>;
// The surfaces' triangles, three vertex indices each.
@group(0) @binding(17) var<storage, read> triangle_indices: array<u32>;
// Per triangle, its surface's 4D area over its own.
@group(0) @binding(18) var<storage, read> area_ratio: array<f32>;
// The stipples placed this frame: written by `stipple_place` (19, 20), drawn from 21.
@group(0) @binding(19) var<storage, read_write> placing: array<Placed>;
@group(0) @binding(20) var<storage, read_write> stipple_draw: StippleDraw;
@group(0) @binding(21) var<storage, read> placed: array<Placed>;

const QUANTUM: f32 = 2147483648.0;
const INK: vec3<f32> = vec3<f32>(0.02, 0.02, 0.02);

// Paper 000 eq. 3: d_new = d_orig + max(0, |2t - 1| - delta_t) delta_d.
fn halo_depth(t: f32, d: f32, delta_t: f32, delta_d: f32) -> f32 {
    return d + max(0.0, abs(2.0 * t - 1.0) - delta_t) * delta_d;
}

fn normalized(depth: f32) -> f32 {
    return (depth - view.depth_norm.x) * view.depth_norm.y;
}

fn colormap(s: f32) -> vec3<f32> {
    let n = view.options.y;
    let x = clamp(s, 0.0, 1.0) * f32(n - 1u);
    let i = min(u32(floor(x)), n - 2u);
    return mix(view.stops[i].rgb, view.stops[i + 1u].rgb, x - f32(i));
}

// The CPU renderer's Phong shading (render::shade::phong), two-sided.
fn phong(base: vec3<f32>, normal: vec3<f32>, dir: vec3<f32>) -> vec3<f32> {
    var n = normal;
    if dot(n, dir) > 0.0 {
        n = -n;
    }
    let to_eye = -dir;
    let right = view.right.xyz;
    let up = view.up.xyz;
    let lights = array<vec4<f32>, 2>(
        vec4<f32>(normalize(to_eye + up * 0.8 - right * 0.6), 0.75),
        vec4<f32>(normalize(to_eye + right * 0.9 - up * 0.2), 0.35),
    );
    var c = base * 0.22;
    for (var k = 0; k < 2; k++) {
        let l = lights[k].xyz;
        let diffuse = max(dot(n, l), 0.0);
        var specular = 0.0;
        if diffuse > 0.0 {
            specular = pow(max(dot(n, normalize(l + to_eye)), 0.0), 40.0);
        }
        c += base * (diffuse * lights[k].w) + vec3<f32>(0.35 * lights[k].w * specular);
    }
    return clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
}

// Whether render.clip removes p (render::clip::Clip::removes): beyond every plane.
fn clipped(p: vec3<f32>) -> bool {
    let n = view.options.z;
    if n == 0u {
        return false;
    }
    for (var k = 0u; k < n; k++) {
        if dot(view.cuts[k].xyz, p) <= view.cuts[k].w {
            return false;
        }
    }
    return true;
}

// Whether p lies on a cut edge of render.clip: within half the lines' width (in pixels,
// measured by the screen derivative of its distance) of a plane, on the kept side, where
// the other plane removes (a wedge's edge) or there is none. The CPU renderer draws these
// edges as lines; the explorer draws the kept surface's fringe along them in the ink.
// Called in uniform control flow (the derivatives need it).
fn on_cut_edge(p: vec3<f32>) -> bool {
    let s = vec2<f32>(dot(view.cuts[0].xyz, p) - view.cuts[0].w, dot(view.cuts[1].xyz, p) - view.cuts[1].w);
    let reach = fwidth(s) * view.viewport.z;
    let n = view.options.z;
    if n == 0u {
        return false;
    }
    let near = s <= vec2<f32>(0.0) & s > -reach;
    if n == 1u {
        return near.x;
    }
    return (near.x && s.y > 0.0) || (near.y && s.x > 0.0);
}

// The direction of the eye ray through p.
fn ray_dir(p: vec3<f32>) -> vec3<f32> {
    if view.eye.w > 0.5 {
        return normalize(p - view.eye.xyz);
    }
    return view.forward.xyz;
}

// ---------------------------------------------------------------- surfaces

struct SurfaceOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) pos: vec3<f32>,
    @location(1) w: f32,
    @location(2) normal: vec3<f32>,
    @location(3) slope: f32,
    @location(4) spread: f32,
    @location(5) @interpolate(flat) slab: u32,
}

@vertex
fn surface_vs(@builtin(vertex_index) i: u32, @builtin(instance_index) slab: u32) -> SurfaceOut {
    let v = vertices[i];
    var out: SurfaceOut;
    out.clip = view.clip * vec4<f32>(v.pos, 1.0);
    out.pos = v.pos;
    out.w = v.w;
    out.normal = v.normal;
    out.slope = v.slope;
    out.spread = v.spread;
    out.slab = slab;
    return out;
}

// Whether a fragment with depth w is hidden, given the normalized halo depth sampled at
// distance at most r from it: below w by more than its own halo can be there (slope r
// for the distance, spread for the tetrahedron's corners around the sample).
fn hidden_by(sample: f32, w: f32, slope: f32, spread: f32, r: f32) -> bool {
    let margin = (slope * r + spread) * view.depth_norm.y + 1e-6;
    return sample < normalized(w) - margin;
}

fn hidden_in_grid(in: SurfaceOut) -> bool {
    if (view.options.x & 1u) == 0u {
        return false;
    }
    let g = (in.pos - view.grid_lo.xyz) / view.grid_lo.w - vec3<f32>(0.5);
    let i = vec3<i32>(round(g));
    let dims = vec3<i32>(view.grid_dims.xyz);
    if any(i < vec3<i32>(0)) || any(i >= dims) {
        return false;
    }
    let v = textureLoad(grid, i, 0).r;
    if v == 0u {
        return false;
    }
    return hidden_by(f32(~v) / QUANTUM, in.w, in.slope, in.spread, view.depth_norm.z);
}

fn view_depth(p: vec3<f32>) -> f32 {
    return dot(p - view.eye.xyz, view.forward.xyz);
}

// The slab a view depth falls in, as the CPU renderer's slice mode assigns it.
fn slab_of(z: f32) -> u32 {
    let k = floor((z - view.slabs.x) / view.slabs.y);
    return u32(clamp(k, 0.0, view.slabs.z - 1.0));
}

fn hidden_in_slab(in: SurfaceOut) -> bool {
    if (view.options.x & 1u) == 0u {
        return false;
    }
    let sample = textureLoad(halo_image, vec2<i32>(floor(in.clip.xy)), 0);
    if sample >= 1.0 {
        return false;
    }
    return hidden_by(sample, in.w, in.slope, in.spread, view.depth_norm.w);
}

fn surface_colour(in: SurfaceOut) -> vec3<f32> {
    if (view.options.x & 8u) != 0u {
        return view.background.rgb;
    }
    var base = vec3<f32>(0.8);
    if (view.options.x & 2u) != 0u {
        base = colormap((in.w - view.w_norm.x) * view.w_norm.y);
    }
    var n = in.normal;
    if dot(n, n) < 1e-20 {
        n = view.forward.xyz;
    }
    return phong(base, normalize(n), ray_dir(in.pos));
}

fn ray_distance(p: vec3<f32>) -> f32 {
    if view.eye.w > 0.5 {
        return length(p - view.eye.xyz);
    }
    return view_depth(p);
}

struct OpaqueOut {
    @location(0) colour: vec4<f32>,
    @location(1) distance: f32,
}

@fragment
fn surface_grid_fs(in: SurfaceOut) -> OpaqueOut {
    let edge = on_cut_edge(in.pos);
    if clipped(in.pos) || hidden_in_grid(in) {
        discard;
    }
    return OpaqueOut(vec4<f32>(select(surface_colour(in), INK, edge), 1.0), ray_distance(in.pos));
}

@fragment
fn surface_view_fs(in: SurfaceOut) -> OpaqueOut {
    let edge = on_cut_edge(in.pos);
    if clipped(in.pos) || slab_of(view_depth(in.pos)) != in.slab || hidden_in_slab(in) {
        discard;
    }
    return OpaqueOut(vec4<f32>(select(surface_colour(in), INK, edge), 1.0), ray_distance(in.pos));
}

// Weighted blended order-independent transparency (McGuire and Bavoil 2013), with paper
// 001's silhouette opacity.
struct BlendOut {
    @location(0) accum: vec4<f32>,
    @location(1) reveal: f32,
}

fn blended(in: SurfaceOut, edge: bool) -> BlendOut {
    let dir = ray_dir(in.pos);
    var n = in.normal;
    if dot(n, n) < 1e-20 {
        n = view.forward.xyz;
    }
    let c = abs(dot(normalize(n), dir));
    var alpha = 1.0 - pow(1.0 - view.background.a, 1.0 / max(c, 0.02));
    if edge {
        alpha = 1.0;
    }
    let d = clamp((view_depth(in.pos) - view.slabs.x) / view.slabs.w, 0.0, 1.0);
    let weight = alpha * clamp(3e3 * pow(1.0 - d, 3.0), 1e-2, 3e3);
    return BlendOut(vec4<f32>(select(surface_colour(in), INK, edge) * weight, weight), alpha);
}

@fragment
fn surface_grid_blend_fs(in: SurfaceOut) -> BlendOut {
    let edge = on_cut_edge(in.pos);
    if clipped(in.pos) || hidden_in_grid(in) {
        discard;
    }
    return blended(in, edge);
}

@fragment
fn surface_view_blend_fs(in: SurfaceOut) -> BlendOut {
    let edge = on_cut_edge(in.pos);
    if clipped(in.pos) || slab_of(view_depth(in.pos)) != in.slab || hidden_in_slab(in) {
        discard;
    }
    return blended(in, edge);
}

// ---------------------------------------------------------------- composite

@vertex
fn composite_vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let x = f32(i32(i & 1u) * 4 - 1);
    let y = f32(i32(i >> 1u) * 4 - 1);
    return vec4<f32>(x, y, 0.0, 1.0);
}

@fragment
fn composite_fs(@builtin(position) frag: vec4<f32>) -> OpaqueOut {
    let at = vec2<i32>(floor(frag.xy));
    let accum = textureLoad(accum_image, at, 0);
    let reveal = textureLoad(reveal_image, at, 0).r;
    let colour = accum.rgb / max(accum.a, 1e-5);
    let alpha = 1.0 - reveal;
    return OpaqueOut(vec4<f32>(mix(view.background.rgb, colour, alpha), 1.0), 0.0);
}

// The average of a pixel's k x k samples (linear colour: the sRGB texels are decoded on
// load and encoded on store).
@fragment
fn downsample_fs(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let k = i32(view.options.w);
    let base = vec2<i32>(floor(frag.xy)) * k;
    var sum = vec4<f32>(0.0);
    for (var y = 0; y < k; y++) {
        for (var x = 0; x < k; x++) {
            sum += textureLoad(samples_image, base + vec2<i32>(x, y), 0);
        }
    }
    return sum / f32(k * k);
}

// ---------------------------------------------------------------- curves

const NOTHING: vec4<f32> = vec4<f32>(2.0, 2.0, 2.0, 1.0);

struct LineOut {
    @builtin(position) clip: vec4<f32>,
    // The line's centre under this fragment: pixel position and view depth.
    @location(0) @interpolate(linear) centre: vec3<f32>,
    // The line's colour (linear).
    @location(1) @interpolate(flat) ink: vec3<f32>,
    // The point of the line under this fragment (for the clip).
    @location(2) pos: vec3<f32>,
}

// The CPU renderer's curve inks (render::overlay::curve_ink): the w scale in OVER_BANDS
// bands, each curve drawn in the colour of the middle of the band of the sheet passing
// over it, darkened by OVER_SHADE.
const OVER_BANDS: f32 = 12.0;
const OVER_SHADE: f32 = 0.35;

// Corner `vertex` (0..6, two triangles) of the segment from p to q drawn as a band
// `viewport.z` pixels either side of it, capped as far beyond its ends.
fn band(p: vec3<f32>, q: vec3<f32>, vertex: u32) -> LineOut {
    var out: LineOut;
    out.ink = INK;
    let a = view.clip * vec4<f32>(p, 1.0);
    let b = view.clip * vec4<f32>(q, 1.0);
    if a.w <= 0.0 || b.w <= 0.0 {
        // Behind the eye: nothing.
        out.clip = NOTHING;
        return out;
    }
    let half_size = view.viewport.xy * 0.5;
    let sa = a.xy / a.w * half_size;
    let sb = b.xy / b.w * half_size;
    var along = sb - sa;
    if dot(along, along) < 1e-12 {
        along = vec2<f32>(1.0, 0.0);
    }
    along = normalize(along) * view.viewport.z;
    let across = vec2<f32>(-along.y, along.x);
    let corners = array<vec2<f32>, 6>(
        vec2<f32>(0.0, -1.0), vec2<f32>(0.0, 1.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(0.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(1.0, -1.0),
    );
    let c = corners[vertex];
    let clip = select(a, b, c.x > 0.5);
    let end = select(sa, sb, c.x > 0.5) + along * (c.x * 2.0 - 1.0);
    let offset = (across * c.y + along * (c.x * 2.0 - 1.0)) / half_size;
    out.clip = vec4<f32>(clip.xy + offset * clip.w, 0.0, clip.w);
    out.pos = select(p, q, c.x > 0.5);
    // Pixels from the top left, as the fragment position.
    out.centre = vec3<f32>(
        half_size.x + end.x,
        half_size.y - end.y,
        view_depth(select(p, q, c.x > 0.5)),
    );
    return out;
}

@vertex
fn curve_vs(@builtin(vertex_index) vertex: u32, @builtin(instance_index) segment: u32) -> LineOut {
    let ends = curve_segments[segment];
    var out = band(curve_points[ends.x].xyz, curve_points[ends.y].xyz, vertex);
    if (view.options.x & 2u) != 0u {
        // The w of the sheet passing over, at the segment's first point.
        let s = clamp((curve_points[ends.x].w - view.w_norm.x) * view.w_norm.y, 0.0, 1.0);
        let b = min(floor(s * OVER_BANDS), OVER_BANDS - 1.0);
        out.ink = colormap((b + 0.5) / OVER_BANDS) * OVER_SHADE;
    }
    return out;
}

// A hyperplane's slice (the explorer's `L`): a curve on the surfaces, drawn as the curves
// are, in magenta, which no colour scale of w has.
const SLICE_INK: vec3<f32> = vec3<f32>(0.75, 0.0, 0.55);

@vertex
fn slice_vs(@builtin(vertex_index) vertex: u32, @builtin(instance_index) segment: u32) -> LineOut {
    let ends = curve_segments[segment];
    var out = band(curve_points[ends.x].xyz, curve_points[ends.y].xyz, vertex);
    out.ink = SLICE_INK;
    return out;
}

// Whether triangle `k`, whose vertex `p` is, faces the eye.
fn facing(k: u32, p: vec3<f32>) -> bool {
    var towards = -view.forward.xyz;
    if view.eye.w > 0.5 {
        towards = view.eye.xyz - p;
    }
    return dot(face_normals[k].xyz, towards) > 0.0;
}

// An edge between a triangle facing the eye and one facing away (as the CPU renderer
// finds them: across a seam of a non-orientable surface the windings disagree, and so do
// the facings of two triangles on the same side), drawn as a band like the curves.
@vertex
fn silhouette_vs(@builtin(vertex_index) vertex: u32, @builtin(instance_index) edge: u32) -> LineOut {
    let e = edges[edge];
    let p = vertices[e.x].pos;
    let agree = (e.w >> 31u) == 1u;
    let j = e.w & 0x7fffffffu;
    if (facing(e.z, p) != facing(j, p)) != agree {
        var out: LineOut;
        out.clip = NOTHING;
        return out;
    }
    return band(p, vertices[e.y].pos, vertex);
}

// The view depth of the surfaces' depth buffer value z.
fn depth_of(z: f32) -> f32 {
    let near = view.depth_proj.x;
    let far = view.depth_proj.y;
    if view.eye.w > 0.5 {
        return near * far / (far - z * (far - near));
    }
    return near + z * (far - near);
}

// A line is drawn where its centre is in view: not behind the farthest surface within a
// pixel of it (by more than its half-width), so that neither the sheets a curve lies
// between nor a surface turning away at its silhouette cover it, while a sheet lying over
// it does.
@fragment
fn line_fs(in: LineOut) -> OpaqueOut {
    if clipped(in.pos) {
        discard;
    }
    if (view.options.x & 4u) != 0u {
        let size = vec2<i32>(view.viewport.xy);
        let at = vec2<i32>(floor(in.centre.xy));
        var farthest = 0.0;
        for (var dy = -1; dy <= 1; dy++) {
            for (var dx = -1; dx <= 1; dx++) {
                let q = clamp(at + vec2<i32>(dx, dy), vec2<i32>(0), size - 1);
                farthest = max(farthest, textureLoad(surface_depth, q, 0));
            }
        }
        var pixel = view.viewport.w;
        if view.eye.w > 0.5 {
            pixel *= in.centre.z;
        }
        if farthest < 1.0 && in.centre.z > depth_of(farthest) + view.viewport.z * pixel {
            discard;
        }
    }
    return OpaqueOut(vec4<f32>(in.ink, 1.0), 0.0);
}

// ---------------------------------------------------------------- halo depth

// The smallest halo depth at the centre of every voxel in one z layer of a tetrahedron's
// box, into the grid buffer (which holds the band of layers from band.y): quantized and complemented, so that atomicMax keeps the
// smallest and 0 (a cleared buffer) means no halo.
@compute @workgroup_size(64)
fn voxelize(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let index = id.x + id.y * groups.x * 64u;
    if index >= view.band.x {
        return;
    }
    let item = items[index];
    let k = tets[item.x];
    let a = halo_vertices[k.x];
    let b = halo_vertices[k.y];
    let c = halo_vertices[k.z];
    let d = halo_vertices[k.w];
    let e1 = b.pos - a.pos;
    let e2 = c.pos - a.pos;
    let e3 = d.pos - a.pos;
    let det = dot(e1, cross(e2, e3));
    let scale = max(max(length(e1), length(e2)), length(e3));
    if abs(det) <= 1e-7 * scale * scale * scale {
        return;
    }
    let r1 = cross(e2, e3) / det;
    let r2 = cross(e3, e1) / det;
    let r3 = cross(e1, e2) / det;
    let lo = min(min(a.pos, b.pos), min(c.pos, d.pos));
    let hi = max(max(a.pos, b.pos), max(c.pos, d.pos));
    let h = view.grid_lo.w;
    let first = vec2<i32>(ceil((lo.xy - view.grid_lo.xy) / h - 0.5));
    let last = vec2<i32>(floor((hi.xy - view.grid_lo.xy) / h - 0.5));
    let x0 = max(first.x, 0);
    let x1 = min(last.x, i32(view.grid_dims.x) - 1);
    let y0 = max(first.y, 0);
    let y1 = min(last.y, i32(view.grid_dims.y) - 1);
    let z = item.y;
    let tol = -1e-6;
    for (var y = y0; y <= y1; y++) {
        for (var x = x0; x <= x1; x++) {
            let centre = view.grid_lo.xyz + (vec3<f32>(f32(x), f32(y), f32(z)) + 0.5) * h;
            let q = centre - a.pos;
            let l1 = dot(r1, q);
            let l2 = dot(r2, q);
            let l3 = dot(r3, q);
            let l0 = 1.0 - l1 - l2 - l3;
            if l0 < tol || l1 < tol || l2 < tol || l3 < tol {
                continue;
            }
            let t = l0 * a.t + l1 * b.t + l2 * c.t + l3 * d.t;
            let dd = l0 * a.d + l1 * b.d + l2 * c.d + l3 * d.d;
            let depth = normalized(halo_depth(t, dd, a.delta_t, a.delta_d));
            let quantized = u32(clamp(depth, 0.0, 0.9999999) * QUANTUM);
            let at = ((z - view.band.y) * view.grid_dims.y + u32(y)) * view.grid_dims.w + u32(x);
            atomicMax(&grid_buffer[at], ~quantized);
        }
    }
}

struct CutOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) t: f32,
    @location(1) d: f32,
    @location(2) @interpolate(flat) delta: vec2<f32>,
}

// Corner `vertex` (0..6, two triangles) of the cut of tetrahedron items[instance].x by the
// plane in the middle of slab items[instance].y; a triangle's second half is empty.
@vertex
fn cut_vs(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> CutOut {
    let item = items[instance];
    let k = tets[item.x];
    let plane = view.slabs.x + (f32(item.y) + 0.5) * view.slabs.y;
    var v = array<HaloVertex, 4>(
        halo_vertices[k.x], halo_vertices[k.y], halo_vertices[k.z], halo_vertices[k.w]
    );
    var s: array<f32, 4>;
    var below: array<u32, 4>;
    var above: array<u32, 4>;
    var nb = 0u;
    var na = 0u;
    for (var i = 0u; i < 4u; i++) {
        s[i] = view_depth(v[i].pos) - plane;
        if s[i] < 0.0 {
            below[nb] = i;
            nb++;
        } else {
            above[na] = i;
            na++;
        }
    }
    // The cut's corners as edges (a, b) crossing the plane, in order around it.
    var edges: array<vec2<u32>, 4>;
    var count = 0u;
    if nb == 1u || nb == 3u {
        var lone = below[0];
        var others = above;
        if nb == 3u {
            lone = above[0];
            others = below;
        }
        edges[0] = vec2<u32>(lone, others[0]);
        edges[1] = vec2<u32>(lone, others[1]);
        edges[2] = vec2<u32>(lone, others[2]);
        count = 3u;
    } else if nb == 2u {
        edges[0] = vec2<u32>(below[0], above[0]);
        edges[1] = vec2<u32>(below[0], above[1]);
        edges[2] = vec2<u32>(below[1], above[1]);
        edges[3] = vec2<u32>(below[1], above[0]);
        count = 4u;
    }
    var out: CutOut;
    out.delta = vec2<f32>(v[0].delta_t, v[0].delta_d);
    let corners = array<u32, 6>(0u, 1u, 2u, 0u, 2u, 3u);
    var corner = corners[vertex];
    if count == 0u || (count == 3u && vertex >= 3u) {
        // Nothing, or the empty half: a degenerate triangle outside the view.
        out.clip = NOTHING;
        out.t = 0.0;
        out.d = 0.0;
        return out;
    }
    let e = edges[corner];
    let a = v[e.x];
    let b = v[e.y];
    let u = s[e.x] / (s[e.x] - s[e.y]);
    let p = mix(a.pos, b.pos, u);
    out.clip = view.clip * vec4<f32>(p, 1.0);
    out.t = mix(a.t, b.t, u);
    out.d = mix(a.d, b.d, u);
    return out;
}

@fragment
fn cut_fs(in: CutOut) -> @builtin(frag_depth) f32 {
    return clamp(normalized(halo_depth(in.t, in.d, in.delta.x, in.delta.y)), 0.0, 0.9999999);
}

// ---------------------------------------------------------------- stipples

// A stipple of `render::stipple`: its triangle (all surfaces), its rank in its surface's
// set and its first two barycentric coordinates.
struct Stipple {
    triangle: u32,
    rank: u32,
    bary: vec2<f32>,
}

// A stipple `stipple_place` decided to draw: its disc's centre in clip space and its colour.
struct Placed {
    clip: vec4<f32>,
    colour: vec4<f32>,
}

// The stipples' indirect draw (wgpu's DrawIndirectArgs): three vertices per placed stipple.
struct StippleDraw {
    vertex_count: atomic<u32>,
    instance_count: u32,
    first_vertex: u32,
    first_instance: u32,
}

struct StippleOut {
    @builtin(position) clip: vec4<f32>,
    // From the disc's centre, in pixels.
    @location(0) offset: vec2<f32>,
    @location(1) @interpolate(flat) colour: vec3<f32>,
}

// Pixels from the top left of clip position c.
fn pixel_of(c: vec4<f32>) -> vec2<f32> {
    let ndc = c.xy / c.w;
    return vec2<f32>((ndc.x * 0.5 + 0.5) * view.viewport.x, (0.5 - ndc.y * 0.5) * view.viewport.y);
}

// render::stipple::luminance (Rec. 709).
fn luminance(c: vec3<f32>) -> f32 {
    return dot(c, vec3<f32>(0.2126, 0.7152, 0.0722));
}

// render::stipple::density: stipples per square pixel that cover a share `tone` with discs
// of diameter `size` pixels.
fn density(tone: f32, size: f32) -> f32 {
    let apart = 0.4;
    let area = 3.14159265 * size * size / 4.0;
    let t = clamp(tone, 0.0, 0.98);
    var x = t;
    if t > apart {
        x = apart - (1.0 - apart) * log((1.0 - t) / (1.0 - apart));
    }
    return x / area;
}

// Stipple `index` placed: its disc's centre in clip space (w 0 when the CPU renderer would
// not draw it) and its colour. The CPU's decision: the tone of
// a white surface under the shaded style's lights at the stipple (normal interpolated, the
// face's where that vanishes), its density per square pixel, times the triangle's screen
// area over its 4D area times the surface's 4D area: the stipple is drawn when its rank is
// below that. Then it must lie on the first surface the halos leave visible at its pixel:
// the depth buffer there (the surfaces' pass, which discards what the halos hide) holds
// that surface's depth at the pixel's centre, up to 0.71 pixel from the stipple. So the
// stipple's triangle's plane is met by the ray through the pixel's centre, and that depth
// is compared: equal where the pixel's centre is on the same triangle, off by the sheet's
// curvature where it is on a neighbour, which grows with the slope (the tangent of the
// angle between the normal and the ray, capped at 20, beyond which the plane is not met
// well and the stipple's own depth is compared). The tolerance is a quarter of a pixel
// plus a fiftieth of a pixel per unit of slope, in scene units of a pixel at the stipple's
// depth, plus 1e-5 of the scene's depth for the f32 depths: it scales with the scene, the
// camera and the surface's slope. A sheet in front, or the stipple's own sheet hidden by a
// halo while one behind shows, is farther off than that, and the stipple is culled. Where
// two sheets cross at a small angle, both are within it along a band and both are stippled
// there; the tolerance is the smallest measured that keeps the tests' tiles within 3% of
// the CPU's (half a pixel plus a tenth per unit of slope let the default scene turned in
// 4D, its inner ring edge-on, reach 7%).
fn place_stipple(index: u32) -> Placed {
    var out: Placed;
    out.clip = vec4<f32>(0.0);
    out.colour = vec4<f32>(INK, 1.0);
    let s = stipples[index];
    let t = s.triangle;
    let a = vertices[triangle_indices[3u * t]];
    let b = vertices[triangle_indices[3u * t + 1u]];
    let c = vertices[triangle_indices[3u * t + 2u]];
    let ca = view.clip * vec4<f32>(a.pos, 1.0);
    let cb = view.clip * vec4<f32>(b.pos, 1.0);
    let cc = view.clip * vec4<f32>(c.pos, 1.0);
    if ca.w <= 0.0 || cb.w <= 0.0 || cc.w <= 0.0 {
        return out;
    }
    let pa = pixel_of(ca);
    let pb = pixel_of(cb);
    let pc = pixel_of(cc);
    let screen = 0.5 * abs((pb.x - pa.x) * (pc.y - pa.y) - (pb.y - pa.y) * (pc.x - pa.x));
    // Most stipples are beyond even the darkest tone's prefix: culled before the lighting.
    let reach = area_ratio[t] * screen;
    if !(f32(s.rank) < density(0.98, view.stipple.x) * reach) {
        return out;
    }
    let l = vec3<f32>(s.bary, 1.0 - s.bary.x - s.bary.y);
    let p = a.pos * l.x + b.pos * l.y + c.pos * l.z;
    if clipped(p) {
        return out;
    }
    let dir = ray_dir(p);
    let face = face_normals[t].xyz;
    var n = a.normal * l.x + b.normal * l.y + c.normal * l.z;
    if !(dot(n, n) > 1e-24) {
        n = face;
    }
    let tone = clamp(1.0 - luminance(phong(vec3<f32>(1.0), normalize(n), dir)), 0.0, 1.0);
    let prefix = density(tone, view.stipple.x) * reach;
    if !(f32(s.rank) < prefix) {
        return out;
    }
    let cp = view.clip * vec4<f32>(p, 1.0);
    if cp.w <= 0.0 {
        return out;
    }
    let centre = pixel_of(cp);
    let size = vec2<i32>(view.viewport.xy);
    let at = clamp(vec2<i32>(floor(centre)), vec2<i32>(0), size - 1);
    let z = textureLoad(surface_depth, at, 0);
    if z >= 1.0 {
        return out;
    }
    // Where the ray through the pixel's centre meets the plane of the stipple's triangle.
    let half_height = view.viewport.w * view.viewport.y * 0.5;
    let half_width = half_height * view.viewport.x / view.viewport.y;
    let ndc = vec2<f32>(
        (f32(at.x) + 0.5) / view.viewport.x * 2.0 - 1.0,
        1.0 - (f32(at.y) + 0.5) / view.viewport.y * 2.0,
    );
    let lateral = view.right.xyz * (ndc.x * half_width) + view.up.xyz * (ndc.y * half_height);
    var origin = view.eye.xyz;
    var ray = view.forward.xyz + lateral;
    if view.eye.w < 0.5 {
        origin += lateral;
        ray = view.forward.xyz;
    }
    var depth = view_depth(p);
    var slope = 20.0;
    if dot(face, face) > 0.0 {
        let nf = normalize(face);
        let cosine = abs(dot(nf, normalize(ray)));
        slope = min(sqrt(max(1.0 - cosine * cosine, 0.0)) / max(cosine, 1e-6), 20.0);
        if slope < 20.0 {
            // The depth along `ray` (whose forward component is 1) is its parameter.
            depth = dot(nf, p - origin) / dot(nf, ray);
        }
    }
    var pixel = view.viewport.w;
    if view.eye.w > 0.5 {
        pixel *= view_depth(p);
    }
    let tolerance = pixel * (0.25 + 0.02 * slope) + 1e-5 * view.slabs.w;
    if abs(depth - depth_of(z)) > tolerance {
        return out;
    }
    if view.stipple.y > 0.5 {
        let w = a.w * l.x + b.w * l.y + c.w * l.z;
        out.colour = vec4<f32>(colormap((w - view.w_norm.x) * view.w_norm.y) * 0.75, 1.0);
    }
    out.clip = cp;
    return out;
}

// Each stipple decided once per frame: the drawn ones are appended to `placing`, three
// vertices each counted in the stipples' indirect draw. Deciding in the vertex shader
// decided every stipple three times (once per corner), and the draw then ran the vertex
// shader for all of them, drawn or not.
@compute @workgroup_size(64)
fn stipple_place(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let index = id.x + id.y * groups.x * 64u;
    if index >= arrayLength(&stipples) {
        return;
    }
    let p = place_stipple(index);
    if p.clip.w > 0.0 {
        placing[atomicAdd(&stipple_draw.vertex_count, 3u) / 3u] = p;
    }
}

// Vertex i of the placed stipples: corner i % 3 of placed stipple i / 3, a triangle whose
// incircle is the stipple's disc. One draw of three vertices per stipple, not instances of
// three: a software rasterizer (lavapipe) shades the vertices of one instance together,
// three lanes of its eight, and the frame took four times as long.
@vertex
fn stipple_vs(@builtin(vertex_index) i: u32) -> StippleOut {
    let p = placed[i / 3u];
    let r = view.stipple.x * 0.5;
    let corners = array<vec2<f32>, 3>(
        vec2<f32>(0.0, 2.0), vec2<f32>(-1.7320508, -1.0), vec2<f32>(1.7320508, -1.0),
    );
    let offset = corners[i % 3u] * r;
    var out: StippleOut;
    out.offset = offset;
    out.colour = p.colour.rgb;
    out.clip = vec4<f32>(p.clip.xy + offset / (view.viewport.xy * 0.5) * p.clip.w, 0.0, p.clip.w);
    return out;
}


@fragment
fn stipple_fs(in: StippleOut) -> @location(0) vec4<f32> {
    let r = view.stipple.x * 0.5;
    if dot(in.offset, in.offset) > r * r {
        discard;
    }
    return vec4<f32>(in.colour, 1.0);
}

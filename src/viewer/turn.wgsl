// halo4d-view: a 4D view's surfaces and halos, rebuilt on the GPU from the 4D mesh (paper 000,
// section 5). Three passes, one thread per item:
// - project (per vertex): rotation, translation and projection of the position and of both
//   tangents (through the projection's Jacobian), as `crate::view::View::project` does;
// - shape (per vertex): the eq. 1 normal (the cross product of the projected tangents; where
//   they are parallel, the sum of the area-weighted normals of the triangles around the
//   vertex; where that vanishes too, +z), the w slope and the longest edge around the vertex
//   (what the renderer's margin reads), and the halo's three vertices, the offsets
//   v -/+ rho n (t = 0, 1, eq. 2) and v itself (t = 1/2), each with d_orig = w, rho
//   limited where the offset would lean far over a triangle around the vertex;
// - faces (per triangle): the triangle's normal as wound (for the silhouettes).
// The tetrahedra do not change with the view (the global vertex order splits every prism the
// same way whatever the geometry), so no pass makes them.

struct Turn {
    rotation: mat4x4<f32>,
    shift: vec4<f32>,
    // xyz: the centre of the view's bounding box (subtracted from every position); w: the 4D
    // eye's distance (0: orthographic).
    centre: vec4<f32>,
    // x: vertices; y: triangles.
    counts: vec4<u32>,
}

struct Point4 {
    p: vec4<f32>,
    tu: vec4<f32>,
    tv: vec4<f32>,
}

// Per surface: x: its halo's first vertex; y: its vertices n; z: 1 when it has a halo.
// Then rho (absolute), delta_t, delta_d.
struct SurfaceInfo {
    halo: vec4<u32>,
    params: vec4<f32>,
}

@group(0) @binding(0) var<uniform> turn: Turn;
@group(0) @binding(1) var<storage, read> points: array<Point4>;
// Per vertex: its surface, its index on the surface, and the range of its triangles in `ring`.
@group(0) @binding(2) var<storage, read> info: array<vec4<u32>>;
@group(0) @binding(3) var<storage, read> ring: array<u32>;
@group(0) @binding(4) var<storage, read> triangles: array<u32>;
@group(0) @binding(5) var<storage, read> surfaces: array<SurfaceInfo>;
@group(0) @binding(6) var<storage, read_write> vertices: array<SurfaceVertex>;
@group(0) @binding(7) var<storage, read_write> halo_vertices: array<HaloVertex>;
@group(0) @binding(8) var<storage, read_write> face_normals: array<vec4<f32>>;
// Per vertex, the projected tangents.
@group(0) @binding(9) var<storage, read_write> frames: array<vec4<f32>>;

// Below this share of |t_u| |t_v|, the projected tangents are parallel (f32 resolves about
// 1e-7 of each).
const PARALLEL: f32 = 1e-5;
// How far an offset may lean over a triangle around its vertex, in the triangle's shorter
// edge there (measured: 0.5 brings the GPU's halos closest to the build's, which shrinks rho
// where prisms invert; see `turn.rs`).
const LIMIT: f32 = 0.5;

fn item(id: vec3<u32>, groups: vec3<u32>) -> u32 {
    return id.x + id.y * groups.x * 64u;
}

@compute @workgroup_size(64)
fn project(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = item(id, groups);
    if i >= turn.counts.x {
        return;
    }
    let point = points[i];
    let q = turn.rotation * point.p + turn.shift;
    let tu = turn.rotation * point.tu;
    let tv = turn.rotation * point.tv;
    var f = 1.0;
    var g = 0.0;
    let e = turn.centre.w;
    if e > 0.0 {
        // d(f xyz) = f dxyz - (f / depth) xyz dw, with f = e / depth (the CPU checked that
        // every depth is positive).
        let depth = q.w + e;
        f = e / depth;
        g = e / (depth * depth);
    }
    vertices[i].pos = q.xyz * f - turn.centre.xyz;
    vertices[i].w = q.w;
    frames[2u * i] = vec4<f32>(tu.xyz * f - q.xyz * (g * tu.w), 0.0);
    frames[2u * i + 1u] = vec4<f32>(tv.xyz * f - q.xyz * (g * tv.w), 0.0);
}

@compute @workgroup_size(64)
fn shape(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = item(id, groups);
    if i >= turn.counts.x {
        return;
    }
    let at = info[i];
    var sum = vec3<f32>(0.0);
    var slope = 0.0;
    var longest = 0.0;
    for (var k = at.z; k < at.w; k++) {
        // Only the members the project pass wrote: this pass writes the others.
        let t = ring[k];
        let ia = triangles[3u * t];
        let ib = triangles[3u * t + 1u];
        let ic = triangles[3u * t + 2u];
        let a = vertices[ia].pos;
        let e1 = vertices[ib].pos - a;
        let e2 = vertices[ic].pos - a;
        let n = cross(e1, e2);
        sum += n;
        longest = max(longest, max(length(e1), max(length(e2), length(e2 - e1))));
        // |grad w| of w linear on the triangle.
        let area2 = dot(n, n);
        if area2 > 0.0 {
            let d1 = vertices[ib].w - vertices[ia].w;
            let d2 = vertices[ic].w - vertices[ia].w;
            let g2 = (d1 * d1 * dot(e2, e2) - 2.0 * d1 * d2 * dot(e1, e2) + d2 * d2 * dot(e1, e1)) / area2;
            slope = max(slope, sqrt(max(g2, 0.0)));
        }
    }
    let tu = frames[2u * i].xyz;
    let tv = frames[2u * i + 1u].xyz;
    var normal = cross(tu, tv);
    if length(normal) > PARALLEL * length(tu) * length(tv) {
        normal = normalize(normal);
    } else if length(sum) > 0.0 {
        normal = normalize(sum);
    } else {
        normal = vec3<f32>(0.0, 0.0, 1.0);
    }
    vertices[i].normal = normal;
    vertices[i].slope = slope;
    vertices[i].spread = slope * longest * 0.25;
    let s = surfaces[at.x];
    if s.halo.z == 0u {
        return;
    }
    // rho where the offsets would lean far over a triangle around the vertex: the offset
    // moves along the surface by rho sin(angle between the offset direction and the
    // triangle's normal), kept below LIMIT times the triangle's shorter edge at the vertex.
    var reach = 3.0e38;
    for (var k = at.z; k < at.w; k++) {
        let t = ring[k];
        let a = vertices[triangles[3u * t]].pos;
        let e1 = vertices[triangles[3u * t + 1u]].pos - a;
        let e2 = vertices[triangles[3u * t + 2u]].pos - a;
        let face = cross(e1, e2);
        if dot(face, face) > 0.0 {
            let c = dot(normalize(face), normal);
            let sine = sqrt(max(1.0 - c * c, 1e-12));
            reach = min(reach, min(length(e1), length(e2)) / sine);
        }
    }
    let rho = min(s.params.x, LIMIT * reach);
    let pos = vertices[i].pos;
    let w = vertices[i].w;
    let base = s.halo.x + at.y;
    let n = s.halo.y;
    halo_vertices[base] = HaloVertex(pos - rho * normal, 0.0, w, s.params.y, s.params.z, 0.0);
    halo_vertices[base + n] = HaloVertex(pos + rho * normal, 1.0, w, s.params.y, s.params.z, 0.0);
    halo_vertices[base + 2u * n] = HaloVertex(pos, 0.5, w, s.params.y, s.params.z, 0.0);
}

@compute @workgroup_size(64)
fn faces(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let t = item(id, groups);
    if t >= turn.counts.y {
        return;
    }
    let a = vertices[triangles[3u * t]].pos;
    let b = vertices[triangles[3u * t + 1u]].pos;
    let c = vertices[triangles[3u * t + 2u]].pos;
    face_normals[t] = vec4<f32>(cross(b - a, c - a), 0.0);
}

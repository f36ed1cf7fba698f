// The vertices both shaders read (`viewer.wgsl`, `turn.wgsl`), as `SurfaceVertex` and
// `HaloVertex` of `src/viewer/mod.rs` lay them out; put in front of each shader.

struct SurfaceVertex {
    pos: vec3<f32>,
    w: f32,
    normal: vec3<f32>,
    slope: f32,
    spread: f32,
    pad0: f32,
    pad1: f32,
    pad2: f32,
}

struct HaloVertex {
    pos: vec3<f32>,
    t: f32,
    d: f32,
    delta_t: f32,
    delta_d: f32,
    pad: f32,
}

//! Colour by w-depth, and Phong shading with two lights in 3D ([`phong`]) or in 4D
//! ([`phong4`]).

use super::Colormap;
use glam::{DMat4, DVec3, DVec4};

/// The colour of w-depth `s` in [0, 1] (0 nearest in w, 1 farthest).
///
/// - `diverging`: blue (near) through light grey to orange (far), the cue of paper 001's
///   colour "growing more amber in the w-direction", readable in grey print.
/// - `viridis`: the perceptually uniform viridis, dark blue (near) to yellow (far),
///   interpolated between eight of its colours.
/// - `gray`: dark (near) to light (far).
pub fn colormap(map: Colormap, s: f64) -> DVec3 {
    let s = if s.is_finite() {
        s.clamp(0.0, 1.0)
    } else {
        0.5
    };
    let stops = stops(map);
    let x = s * (stops.len() - 1) as f64;
    let i = (x.floor() as usize).min(stops.len() - 2);
    let f = x - i as f64;
    DVec3::from(stops[i]).lerp(DVec3::from(stops[i + 1]), f)
}

/// The colours of `map`, nearest in w first, evenly spaced.
pub(crate) fn stops(map: Colormap) -> &'static [[f64; 3]] {
    match map {
        Colormap::Diverging => &[
            [0.23, 0.30, 0.75],
            [0.55, 0.65, 0.92],
            [0.87, 0.87, 0.87],
            [0.96, 0.66, 0.42],
            [0.85, 0.42, 0.10],
        ],
        Colormap::Viridis => &[
            [0.267, 0.005, 0.329],
            [0.275, 0.194, 0.496],
            [0.213, 0.359, 0.552],
            [0.153, 0.498, 0.558],
            [0.122, 0.632, 0.530],
            [0.290, 0.762, 0.428],
            [0.626, 0.854, 0.223],
            [0.993, 0.906, 0.144],
        ],
        Colormap::Gray => &[[0.25, 0.25, 0.25], [0.9, 0.9, 0.9]],
    }
}

/// Phong shading of a surface of colour `base` with unit normal `n` seen along unit `view`
/// (from the eye), lit by a key light above left of the camera and a fill light right of
/// it (both fixed to the camera), two-sided.
pub fn phong(base: DVec3, n: DVec3, view: DVec3, right: DVec3, up: DVec3) -> DVec3 {
    let n = if n.dot(view) > 0.0 { -n } else { n };
    let to_eye = -view;
    let mut c = base * 0.22;
    for (l, strength) in lights(view, right, up) {
        let diffuse = n.dot(l).max(0.0);
        let h = (l + to_eye).normalize();
        let specular = if diffuse > 0.0 {
            n.dot(h).max(0.0).powi(40)
        } else {
            0.0
        };
        c += base * (diffuse * strength) + DVec3::splat(0.35 * strength * specular);
    }
    c.clamp(DVec3::ZERO, DVec3::ONE)
}

/// The two lights of [`phong`], fixed to the camera (`view` from the eye, `right`, `up`):
/// unit directions towards them and their strengths.
fn lights(view: DVec3, right: DVec3, up: DVec3) -> [(DVec3, f64); 2] {
    let to_eye = -view;
    [
        ((to_eye + up * 0.8 - right * 0.6).normalize(), 0.75),
        ((to_eye + right * 0.9 - up * 0.2).normalize(), 0.35),
    ]
}

/// How far [`phong4`]'s lights lean out of the picture's 3D space towards +w, in degrees.
pub const LIGHT_W_TILT: f64 = 25.0;

/// The tangent plane of a surface in 4D as its orthogonal projector `t1 t1ᵀ + t2 t2ᵀ` (for
/// any orthonormal basis `t1`, `t2` of the plane spanned by `e1` and `e2`): it does not
/// depend on the basis or its orientation, so the planes of the vertices of a
/// non-orientable surface average without cancelling. `None` where `e1` and `e2` span no
/// plane.
pub fn tangent_projector(e1: DVec4, e2: DVec4) -> Option<DMat4> {
    let t1 = e1.try_normalize()?;
    let t2 = (e2 - t1 * t1.dot(e2)).try_normalize()?;
    let outer = |t: DVec4| DMat4::from_cols(t * t.x, t * t.y, t * t.z, t * t.w);
    Some(outer(t1) + outer(t2))
}

/// Per vertex, the area-weighted mean of the tangent projectors ([`tangent_projector`]) of
/// its triangles, in the 4D frame of the picture: a vertex's 3D position with its w-depth
/// as the fourth coordinate (for an orthographic 4D projection, the turned surface itself).
/// The zero matrix at a vertex of no triangle with an area.
pub fn vertex_tangent_projectors(
    positions: &[DVec3],
    w: &[f64],
    triangles: &[[u32; 3]],
) -> Vec<DMat4> {
    let at = |v: u32| positions[v as usize].extend(w[v as usize]);
    let mut sum = vec![DMat4::ZERO; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(at);
        let (e1, e2) = (b - a, c - a);
        // The area of the triangle in 4D (Lagrange's identity).
        let area = (e1.length_squared() * e2.length_squared() - e1.dot(e2).powi(2))
            .max(0.0)
            .sqrt();
        let Some(p) = tangent_projector(e1, e2).filter(|_| area.is_finite()) else {
            continue;
        };
        for &v in t {
            sum[v as usize] += p * area;
        }
    }
    for p in &mut sum {
        // The weights sum to the trace (each projector's is 2).
        let trace = p.x_axis.x + p.y_axis.y + p.z_axis.z + p.w_axis.w;
        *p = if trace > 0.0 && trace.is_finite() {
            *p * (2.0 / trace)
        } else {
            DMat4::ZERO
        };
    }
    sum
}

/// Phong shading in 4D (Hanson and Heng's illumination of surfaces in four dimensions): a
/// surface of colour `base` whose tangent plane has the projector `plane` (a mean of
/// [`tangent_projector`]s) lit by [`phong`]'s two lights leaned [`LIGHT_W_TILT`] towards +w.
/// A surface in 4D has a plane of normals, so the diffuse term is the length of the light's
/// component in that plane, `sqrt(1 - lᵀ P l)`, and the specular one that of the halfway
/// vector's; both need no orientation. A surface lying in a hyperplane w = const has the
/// normal plane spanned by its 3D normal and w: its diffuse term is `sqrt((n·l)² cos² θ +
/// sin² θ)` for the tilt θ, and what varies the shade is how the tangent plane leans in w.
pub fn phong4(base: DVec3, plane: DMat4, view: DVec3, right: DVec3, up: DVec3) -> DVec3 {
    let (sin, cos) = LIGHT_W_TILT.to_radians().sin_cos();
    let to_eye = (-view).extend(0.0);
    let normal_length = |d: DVec4| (1.0 - d.dot(plane * d)).clamp(0.0, 1.0).sqrt();
    let mut c = base * 0.22;
    for (l, strength) in lights(view, right, up) {
        let l = (l * cos).extend(sin);
        let diffuse = normal_length(l);
        let specular = normal_length((l + to_eye).normalize()).powi(40);
        c += base * (diffuse * strength) + DVec3::splat(0.35 * strength * specular);
    }
    c.clamp(DVec3::ZERO, DVec3::ONE)
}

/// The shading normal at barycentric point `bary` of the triangle with corners `p` and
/// vertex normals `n`: each vertex normal turned to the side of the triangle's own normal
/// before they are interpolated, then normalized; the triangle's normal where they cancel.
///
/// Vertex normals of one triangle can point to opposite sides: across the line where a
/// non-orientable surface (the Klein bottle, the projective plane) turns over, and around
/// cross-caps of a projection. Interpolated as they are, they pass through zero inside the
/// triangle and its shading jumps from light to dark along a jagged line of mesh edges.
/// Shading is two-sided ([`phong`]), so the side a normal points to carries nothing else.
pub fn shading_normal(p: [DVec3; 3], n: [DVec3; 3], bary: [f64; 3]) -> DVec3 {
    let face = (p[1] - p[0]).cross(p[2] - p[0]);
    let mut mixed = DVec3::ZERO;
    for k in 0..3 {
        let side = if n[k].dot(face) < 0.0 { -1.0 } else { 1.0 };
        mixed += n[k] * (side * bary[k]);
    }
    if mixed.length_squared() <= 1e-24 || !mixed.is_finite() {
        return face.normalize_or_zero();
    }
    mixed.normalize()
}

/// Paper 001's silhouette opacity: a surface of opacity `alpha` seen at |cos| = `d`
/// between the eye ray and its normal covers 1 - (1 - alpha)^(1/d), as a sheet of that
/// opacity would when crossed obliquely: rims become opaque, faces stay clear.
pub fn silhouette_opacity(alpha: f64, d: f64) -> f64 {
    if alpha >= 1.0 {
        return 1.0;
    }
    1.0 - (1.0 - alpha).powf(1.0 / d.abs().max(0.02))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colormaps_run_from_their_first_to_their_last_stop() {
        for map in [Colormap::Diverging, Colormap::Viridis, Colormap::Gray] {
            let (a, b) = (colormap(map, 0.0), colormap(map, 1.0));
            assert!(a.is_finite() && b.is_finite() && (a - b).length() > 0.3);
            assert_eq!(colormap(map, f64::NAN), colormap(map, 0.5));
        }
    }

    #[test]
    fn shading_normals_of_opposite_vertices_keep_to_the_triangles_side() {
        let p = [DVec3::ZERO, DVec3::X, DVec3::Y];
        // A Klein bottle's seam: one corner's normal points down, the others up.
        let n = [DVec3::Z, -DVec3::Z, (DVec3::Z + DVec3::X).normalize()];
        let steps = 20;
        for i in 0..=steps {
            for j in 0..=steps - i {
                let (a, b) = (i as f64 / steps as f64, j as f64 / steps as f64);
                let m = shading_normal(p, n, [a, b, 1.0 - a - b]);
                assert!((m.length() - 1.0).abs() < 1e-12);
                assert!(m.z > 0.7, "{m} at ({a}, {b})");
            }
        }
        // Interpolated as they are, they cancel at the middle of the first edge.
        let raw = (n[0] + n[1]) * 0.5;
        assert!(raw.length() < 1e-12);
        // Normals that cancel even when turned: the triangle's own.
        let flat = shading_normal(p, [DVec3::X, -DVec3::X, DVec3::X], [0.5, 0.5, 0.0]);
        assert_eq!(flat, DVec3::Z);
    }

    #[test]
    fn four_d_shading_of_a_flat_surface_is_that_of_its_normal_plane() {
        let (view, right, up) = (-DVec3::Z, DVec3::X, DVec3::Y);
        let base = DVec3::new(0.5, 0.6, 0.7);
        let lit = |plane| phong4(base, plane, view, right, up);
        // The plane z = w = 0 in either orientation and basis: one projector, one shade.
        let p = tangent_projector(DVec4::X, DVec4::Y).unwrap();
        let q = tangent_projector(DVec4::new(1.0, 1.0, 0.0, 0.0), -DVec4::X).unwrap();
        assert!((p - q).abs_diff_eq(DMat4::ZERO, 1e-15));
        assert_eq!(lit(p), lit(q));
        // Its normal plane is (z, w): each light's diffuse term is the length of its
        // (z, w) part, the specular term that of the halfway vector's.
        let (sin, cos) = LIGHT_W_TILT.to_radians().sin_cos();
        let mut expect = base * 0.22;
        for (l, strength) in lights(view, right, up) {
            let l4 = (l * cos).extend(sin);
            let h = (l4 + DVec4::Z).normalize();
            let diffuse = (l4.z * l4.z + l4.w * l4.w).sqrt();
            let specular = (h.z * h.z + h.w * h.w).sqrt().powi(40);
            expect += base * (diffuse * strength) + DVec3::splat(0.35 * strength * specular);
        }
        let expect = expect.clamp(DVec3::ZERO, DVec3::ONE);
        assert!((lit(p) - expect).length() < 1e-12, "{} {expect}", lit(p));
        // Tilted into w, the same plane in 3D reads differently: the 4D cue.
        let tilted = tangent_projector(DVec4::new(1.0, 0.0, 0.0, 1.0), DVec4::Y).unwrap();
        assert!((lit(tilted) - lit(p)).length() > 0.02);
        // Without a plane (no triangle with an area), the surface is lit all over.
        assert!(lit(DMat4::ZERO).is_finite());
        assert_eq!(tangent_projector(DVec4::X, DVec4::X * 2.0), None);
    }

    #[test]
    fn vertex_projectors_average_their_triangles_planes() {
        // Two triangles folded along the x axis: one in the xy plane, one in the xw plane.
        let positions = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::ZERO];
        let w = [0.0, 0.0, 0.0, 1.0];
        let triangles = [[0, 1, 2], [1, 0, 3]];
        let p = vertex_tangent_projectors(&positions, &w, &triangles);
        let xy = tangent_projector(DVec4::X, DVec4::Y).unwrap();
        let xw = tangent_projector(DVec4::X, DVec4::W).unwrap();
        assert!(p[2].abs_diff_eq(xy, 1e-15) && p[3].abs_diff_eq(xw, 1e-15));
        assert!(p[0].abs_diff_eq((xy + xw) * 0.5, 1e-15));
        // A vertex of no triangle has none.
        let p = vertex_tangent_projectors(&[DVec3::ZERO], &[0.0], &[]);
        assert_eq!(p, vec![DMat4::ZERO]);
    }

    #[test]
    fn silhouette_opacity_is_alpha_face_on_and_grows_towards_the_rim() {
        assert!((silhouette_opacity(0.3, 1.0) - 0.3).abs() < 1e-12);
        assert!(silhouette_opacity(0.3, 0.2) > 0.8);
        assert_eq!(silhouette_opacity(1.0, 0.5), 1.0);
    }
}

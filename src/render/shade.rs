//! Colour by w-depth and Phong shading with two lights.

use super::Colormap;
use glam::DVec3;

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
    let lights = [
        ((to_eye + up * 0.8 - right * 0.6).normalize(), 0.75),
        ((to_eye + right * 0.9 - up * 0.2).normalize(), 0.35),
    ];
    let mut c = base * 0.22;
    for (l, strength) in lights {
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
    fn silhouette_opacity_is_alpha_face_on_and_grows_towards_the_rim() {
        assert!((silhouette_opacity(0.3, 1.0) - 0.3).abs() < 1e-12);
        assert!(silhouette_opacity(0.3, 0.2) > 0.8);
        assert_eq!(silhouette_opacity(1.0, 0.5), 1.0);
    }
}

//! Wavefront OBJ with four numbers per vertex.

use super::*;

// OBJ's optional fourth number of `v` is officially a homogeneous weight, and tobj 4 reads it
// into the colour array; here it is the coordinate w, hence a reader of our own.
pub(super) fn obj(bytes: &[u8], cx: Cx) -> Result<MeshData4> {
    let text = utf8(bytes, 1, cx)?;
    let mut lines = Lines::new(text, 1, true);
    let mut build = Build::default();
    let mut faces = 0;
    let mut raw = Vec::new();
    while let Some((n, words)) = lines.next() {
        match words[0] {
            "v" => {
                let v = build.mesh.positions.len() + 1;
                let numbers = &words[1..];
                if numbers.len() == 3 {
                    return Err(cx.line(
                        n,
                        format!(
                            "vertex {v} has 3 coordinates; halo4d needs the fourth coordinate w: `v x y z w` (not a homogeneous weight here)"
                        ),
                    ));
                }
                if numbers.len() != 4 {
                    return Err(cx.line(
                        n,
                        format!(
                            "vertex {v} has {} numbers; halo4d reads `v x y z w`",
                            numbers.len()
                        ),
                    ));
                }
                if v > MAX_COUNT {
                    return Err(cx.line(
                        n,
                        format!("more than {MAX_COUNT} vertices, the most halo4d reads"),
                    ));
                }
                let mut p = [0.0; 4];
                for (axis, w) in numbers.iter().enumerate() {
                    p[axis] = coordinate(w, v, axis).map_err(|m| cx.line(n, m))?;
                }
                build.mesh.positions.push(DVec4::from_array(p));
            }
            "f" => {
                faces += 1;
                raw.clear();
                for w in &words[1..] {
                    let mut parts = w.split('/');
                    let index = parts.next().and_then(|i| i.parse::<i64>().ok());
                    let others_ok = parts.clone().count() <= 2
                        && parts.all(|p| p.is_empty() || p.parse::<i64>().is_ok());
                    match index {
                        Some(i) if others_ok => raw.push(i),
                        _ => {
                            return Err(cx.line(
                                n,
                                format!(
                                    "face {faces}: `{}` is not a vertex reference (`i`, `i/t`, `i//n` or `i/t/n`)",
                                    shorten(w)
                                ),
                            ));
                        }
                    }
                }
                build.face(&raw, faces, true).map_err(|m| cx.line(n, m))?;
            }
            _ => {}
        }
    }
    build.finish().map_err(|m| cx.line(lines.last(), m))
}

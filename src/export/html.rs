//! `<name>.html` (`outputs.html`): a page that shows the scene's `.glb` in a web browser, for
//! sharing a figure. It holds everything it needs: three.js (0.187.0's WebGL renderer,
//! GLTFLoader and OrbitControls, bundled and minified by `assets/viewer/bundle.sh` into
//! `assets/viewer/three.min.js`, MIT licence kept at its head), the page's script
//! (`assets/viewer/page.js`) and the `.glb` itself as base64. So it opens from a file
//! (`file://`, where a module script could not import three.js beside it, and a page cannot
//! fetch the `.glb` next to it), offline, with no request to another site and no version of
//! three.js that can change under it; the price is about 640 KB of script in every page and
//! a third more than the `.glb` for its bytes.
//!
//! The page shows the file's default glTF scene through its camera ([`super::Figure`]): the
//! surfaces in the picture's colours of w and the curves' tubes, the halos (the file's second
//! scene) hidden behind a checkbox; drag to turn about the picture's centre, scroll to zoom.

use base64::Engine;
use std::io::{self, Write};

/// three.js as the page inlines it (see the module documentation).
const THREE: &str = include_str!("../../assets/viewer/three.min.js");

/// The page's own script.
const SCRIPT: &str = include_str!("../../assets/viewer/page.js");

/// Writes the page for the `.glb` bytes `glb` of scene `title`, on the picture's
/// `background` (linear RGB in [0, 1]), to `out`.
pub fn write_html(
    out: &mut dyn Write,
    title: &str,
    glb: &[u8],
    background: [f64; 3],
) -> io::Result<()> {
    let settings = serde_json::json!({
        "background": background.map(|c| if c.is_finite() { c.clamp(0.0, 1.0) } else { 1.0 }),
        "halo_scene": super::HALO_SCENE,
    });
    let title = escape(title);
    write!(
        out,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <meta name=\"generator\" content=\"halo4d {version}\">\n\
         <title>{title}</title>\n<style>\n\
         html, body {{ margin: 0; height: 100%; overflow: hidden; }}\n\
         canvas {{ display: block; }}\n\
         #halo4d-bar {{ position: fixed; left: 8px; bottom: 8px; font: 13px sans-serif; \
         color: #333; background: rgba(255, 255, 255, 0.75); padding: 2px 6px; }}\n\
         </style>\n</head>\n<body>\n\
         <div id=\"halo4d-bar\">{title}: drag to turn, scroll to zoom \
         <label><input type=\"checkbox\" id=\"halo4d-halos\"> halos</label> \
         <span id=\"halo4d-status\"></span></div>\n\
         <script id=\"halo4d-page\" type=\"application/json\">{settings}</script>\n\
         <script id=\"halo4d-glb\" type=\"model/gltf-binary;base64\">",
        version = env!("CARGO_PKG_VERSION"),
    )?;
    // In lines of 76 characters, encoded a line at a time: no second copy of the file.
    for chunk in glb.chunks(57) {
        out.write_all(
            base64::engine::general_purpose::STANDARD
                .encode(chunk)
                .as_bytes(),
        )?;
        out.write_all(b"\n")?;
    }
    out.write_all(b"</script>\n<script>\n")?;
    out.write_all(THREE.as_bytes())?;
    out.write_all(b"\n</script>\n<script>\n")?;
    out.write_all(SCRIPT.as_bytes())?;
    out.write_all(b"</script>\n</body>\n</html>\n")
}

/// `text` with the characters HTML gives a meaning escaped.
fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::{SCRIPT, THREE, escape, write_html};

    #[test]
    fn the_inlined_scripts_cannot_end_their_script_element() {
        for (name, text) in [("three.min.js", THREE), ("page.js", SCRIPT)] {
            assert!(
                !text.to_ascii_lowercase().contains("</script"),
                "{name} holds `</script`, which would end the page's script early"
            );
        }
    }

    #[test]
    fn the_page_embeds_the_glb_whole_and_escapes_the_title() {
        use base64::Engine;
        let glb: Vec<u8> = (0..=255u8).cycle().take(1000).collect();
        let mut page = Vec::new();
        write_html(&mut page, "a <b> & \"c\"", &glb, [1.0, f64::NAN, 0.5]).unwrap();
        let page = String::from_utf8(page).unwrap();
        assert!(page.contains("<title>a &lt;b&gt; &amp; &quot;c&quot;</title>"));
        assert!(page.contains("\"background\":[1.0,1.0,0.5]"));
        let start = page.find("base64\">").unwrap() + "base64\">".len();
        let end = start + page[start..].find("</script>").unwrap();
        let text: String = page[start..end].split_whitespace().collect();
        let back = base64::engine::general_purpose::STANDARD
            .decode(text)
            .unwrap();
        assert_eq!(back, glb);
        assert_eq!(escape("plain"), "plain");
    }
}

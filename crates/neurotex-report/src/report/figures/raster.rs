//! Every figure as PNG too, rendered from its SVG in-process (resvg), at print resolution.
//!
//! The font is Noto Sans Regular, compiled into the binary (the `ttf-noto-sans` crate), and
//! it is the only font resvg is given: no system font is looked up. resvg, like any SVG
//! renderer, leaves out a text whose font it cannot find, without an error; a fresh Debian
//! image, a slim container or a CI runner often has no font at all (fontconfig finds
//! nothing), and its PNGs would have lost every title, tick and legend. With the bundled
//! font every machine draws the same pixels, and the layouts can be measured with the
//! font they are drawn in ([`super::plot::text_width`]). The font file is plain data (Google's
//! Noto Sans, Apache-2.0), so the crate carrying it needs no upkeep. A character Noto Sans
//! lacks (CJK, say, in a class name) is drawn as its empty-box glyph, visibly, and the SVG
//! beside the PNG keeps the text for the viewer's fonts.

use std::sync::{Arc, OnceLock};

use resvg::tiny_skia::{Pixmap, Transform};
use resvg::usvg::{self, fontdb, Node, Tree};

use super::plot::{DPI, FONT_DATA};
use super::FigureError;

/// The family name of the font every figure is set in ([`FONT_DATA`]), as it names itself.
const FONT_FAMILY: &str = "Noto Sans";
/// The PNG's resolution: 300 dpi at the figure's paper width.
pub(crate) const PNG_DPI: f64 = 300.0;

/// The fonts resvg may use: the bundled one alone, standing for every generic family, so
/// that `sans-serif` and any family name a figure asks for resolve to it.
fn fonts() -> Arc<fontdb::Database> {
    static FONTS: OnceLock<Arc<fontdb::Database>> = OnceLock::new();
    FONTS
        .get_or_init(|| {
            let mut db = fontdb::Database::new();
            db.load_font_source(fontdb::Source::Binary(Arc::new(FONT_DATA)));
            db.set_sans_serif_family(FONT_FAMILY);
            db.set_serif_family(FONT_FAMILY);
            Arc::new(db)
        })
        .clone()
}

/// The PNG of `svg` at [`PNG_DPI`] (the SVG's pixels are [`DPI`] to the inch), RGB on the
/// SVG's white background, its resolution recorded in the file (`pHYs`) so that a word
/// processor or LaTeX places it at the figure's paper width.
///
/// # Errors
/// The SVG does not parse, a text of it was left out (no font could set it), or encoding
/// fails.
pub fn png(svg: &str) -> Result<Vec<u8>, FigureError> {
    png_with(svg, fonts())
}

/// [`png`] with the fonts `fontdb`.
fn png_with(svg: &str, fontdb: Arc<fontdb::Database>) -> Result<Vec<u8>, FigureError> {
    let options = usvg::Options {
        font_family: FONT_FAMILY.into(),
        fontdb,
        ..usvg::Options::default()
    };
    let tree = Tree::from_str(svg, &options).map_err(|e| FigureError(format!("SVG: {e}")))?;
    check_texts(svg, &tree)?;
    let scale = (PNG_DPI / DPI) as f32;
    let size = tree.size();
    let (width, height) = (
        (size.width() * scale).round() as u32,
        (size.height() * scale).round() as u32,
    );
    let mut pixmap = Pixmap::new(width, height)
        .ok_or_else(|| FigureError(format!("a PNG of {width} x {height} pixels")))?;
    pixmap.fill(resvg::tiny_skia::Color::WHITE);
    resvg::render(
        &tree,
        Transform::from_scale(scale, scale),
        &mut pixmap.as_mut(),
    );
    encode(&pixmap)
}

/// Fails when a text of `svg` with something to show is missing from `tree` or drew no
/// glyph: resvg leaves out, with no more than a log line, a text no font can set.
fn check_texts(svg: &str, tree: &Tree) -> Result<(), FigureError> {
    let wanted = svg
        .split("<text")
        .skip(1)
        .filter(|part| {
            let content = part.find('>').map_or("", |open| {
                let rest = &part[open + 1..];
                &rest[..rest.find("</text>").unwrap_or(rest.len())]
            });
            !content.trim().is_empty()
        })
        .count();
    let drawn = drawn_texts(tree.root());
    if drawn < wanted {
        return Err(FigureError(format!(
            "{} of {wanted} texts drew no glyph (no font could set them)",
            wanted - drawn
        )));
    }
    Ok(())
}

/// Texts under `group` with something visible and at least one glyph outline.
fn drawn_texts(group: &usvg::Group) -> usize {
    group
        .children()
        .iter()
        .map(|node| match node {
            Node::Group(g) => drawn_texts(g),
            Node::Text(t) => {
                let visible = t.chunks().iter().any(|c| !c.text().trim().is_empty());
                usize::from(visible && t.flattened().has_children())
            }
            _ => 0,
        })
        .sum()
}

/// `pixmap` as an 8-bit RGB PNG at [`PNG_DPI`]. The figures paint a white background over
/// the whole canvas, so every pixel is opaque and the alpha channel carries nothing.
fn encode(pixmap: &Pixmap) -> Result<Vec<u8>, FigureError> {
    let rgb: Vec<u8> = pixmap
        .pixels()
        .iter()
        .flat_map(|p| {
            let c = p.demultiply();
            [c.red(), c.green(), c.blue()]
        })
        .collect();
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, pixmap.width(), pixmap.height());
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let per_metre = (PNG_DPI / 0.0254).round() as u32;
    encoder.set_pixel_dims(Some(png::PixelDimensions {
        xppu: per_metre,
        yppu: per_metre,
        unit: png::Unit::Meter,
    }));
    let failed = |e: png::EncodingError| FigureError(format!("PNG: {e}"));
    let mut writer = encoder.write_header().map_err(failed)?;
    writer.write_image_data(&rgb).map_err(failed)?;
    writer.finish().map_err(failed)?;
    Ok(out)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The decoded PNG: `(width, height, RGB bytes)`.
    pub(crate) fn decode(png: &[u8]) -> (u32, u32, Vec<u8>) {
        let decoder = png::Decoder::new(std::io::Cursor::new(png));
        let mut reader = decoder.read_info().expect("a PNG header");
        let mut buf = vec![0; reader.output_buffer_size().expect("a size")];
        let info = reader.next_frame(&mut buf).expect("a PNG frame");
        assert_eq!(info.color_type, png::ColorType::Rgb);
        buf.truncate(info.buffer_size());
        (info.width, info.height, buf)
    }

    /// Pixels darker than light grey in the rows `y0..y1` (of the PNG's height) and the
    /// columns `x0..x1`.
    pub(crate) fn dark_pixels(
        (width, _, rgb): &(u32, u32, Vec<u8>),
        (x0, x1): (u32, u32),
        (y0, y1): (u32, u32),
    ) -> usize {
        (y0..y1)
            .flat_map(|y| (x0..x1).map(move |x| ((y * width + x) * 3) as usize))
            .filter(|&i| rgb[i..i + 3].iter().map(|&v| u32::from(v)).sum::<u32>() < 3 * 160)
            .count()
    }

    const TEXT_SVG: &str = r##"<svg width="96" height="24" viewBox="0 0 96 24" xmlns="http://www.w3.org/2000/svg"><rect x="0" y="0" width="96" height="24" fill="#FFFFFF"/><text x="4" y="18" font-family="sans-serif" font-size="14" fill="#000000">Hello 42 %</text></svg>"##;

    #[test]
    fn text_is_drawn_at_print_resolution_with_the_dpi_recorded() {
        let png = png(TEXT_SVG).unwrap();
        let image = decode(&png);
        // 96 x 24 CSS pixels at 300 dpi
        assert_eq!((image.0, image.1), (300, 75));
        assert!(dark_pixels(&image, (0, 300), (0, 75)) > 300, "text drawn");
        let reader = png::Decoder::new(std::io::Cursor::new(&png))
            .read_info()
            .unwrap();
        let dims = reader.info().pixel_dims.unwrap();
        assert_eq!((dims.xppu, dims.unit), (11811, png::Unit::Meter));
    }

    #[test]
    fn any_family_resolves_to_the_bundled_font() {
        let serif = TEXT_SVG.replace("sans-serif", "No Such Font, serif");
        let image = decode(&png(&serif).unwrap());
        assert!(dark_pixels(&image, (0, 300), (0, 75)) > 300);
    }

    #[test]
    fn without_a_font_a_text_is_an_error_not_a_blank() {
        let empty = Arc::new(fontdb::Database::new());
        let err = png_with(TEXT_SVG, empty).unwrap_err();
        assert!(err.to_string().contains("1 of 1 texts"), "{err}");
        // a figure without text needs no font
        let no_text = TEXT_SVG.replace("Hello 42 %", " ");
        assert!(png_with(&no_text, Arc::new(fontdb::Database::new())).is_ok());
    }

    #[test]
    fn a_character_the_font_lacks_still_leaves_a_mark() {
        let cjk = TEXT_SVG.replace("Hello 42 %", "布料");
        let image = decode(&png(&cjk).unwrap());
        assert!(dark_pixels(&image, (0, 300), (0, 75)) > 50);
    }
}

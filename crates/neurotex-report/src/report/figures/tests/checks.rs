//! The checks every figure passes: well-formed SVG on its canvas, no overprinted or
//! clipped text, a paper width, and a PNG of the same figure.

use super::*;

/// The canvas size of an SVG document, from its root element.
fn canvas_size(svg: &str) -> (f64, f64) {
    let attr = |name: &str| -> f64 {
        let key = format!(" {name}=\"");
        let start = svg.find(&key).expect("size attribute") + key.len();
        let end = start + svg[start..].find('"').unwrap();
        svg[start..end].parse().unwrap()
    };
    (attr("width"), attr("height"))
}

/// Checks that `svg` is one `<svg>` element whose tags nest and close, with no NaN or
/// infinite numbers, and whose text anchors lie on the canvas.
pub(crate) fn assert_well_formed(name: &str, svg: &str) {
    assert!(
        svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"),
        "{name}: not one svg element"
    );
    for bad in ["NaN", "inf\"", "-inf"] {
        assert!(!svg.contains(bad), "{name}: contains {bad}");
    }
    let (width, height) = canvas_size(svg);
    let mut stack: Vec<String> = Vec::new();
    let mut rest = svg;
    while let Some(open) = rest.find('<') {
        let close = rest[open..].find('>').expect("unclosed tag") + open;
        let tag = &rest[open + 1..close];
        if let Some(name_closed) = tag.strip_prefix('/') {
            let top = stack.pop().unwrap_or_default();
            assert_eq!(
                top,
                name_closed.trim(),
                "{name}: </{name_closed}> closes <{top}>"
            );
        } else if !tag.ends_with('/') {
            stack.push(tag.split_whitespace().next().unwrap_or("").to_string());
        }
        if tag.starts_with("text ") {
            let attr = |key: &str| -> f64 {
                let k = format!(" {key}=\"");
                let s = tag.find(&k).unwrap() + k.len();
                tag[s..s + tag[s..].find('"').unwrap()].parse().unwrap()
            };
            let (x, y) = (attr("x"), attr("y"));
            assert!(
                (0.0..=width).contains(&x) && (0.0..=height).contains(&y),
                "{name}: text at ({x}, {y}) off the {width}x{height} canvas"
            );
        }
        rest = &rest[close + 1..];
    }
    assert!(stack.is_empty(), "{name}: unclosed {stack:?}");
}

/// A level text's box `(x0, y0, x1, y1)` in pixels, measured with the figures' font, and
/// its anchors.
fn text_box(tag: &str, content: &str) -> Option<(f64, f64, f64, f64)> {
    let attr = |key: &str| -> Option<&str> {
        let k = format!(" {key}=\"");
        let s = tag.find(&k)? + k.len();
        Some(&tag[s..s + tag[s..].find('"')?])
    };
    if attr("transform").is_some() {
        return None;
    }
    let (x, y): (f64, f64) = (attr("x")?.parse().ok()?, attr("y")?.parse().ok()?);
    let size: f64 = attr("font-size")?.parse().ok()?;
    let w = f64::from(plot::text_width(content, size * 1.24));
    let x0 = match attr("text-anchor")? {
        "start" => x,
        "end" => x - w,
        _ => x - w / 2.0,
    };
    let y0 = match attr("dy")? {
        "0.76em" => y,
        "-0.5ex" => y - size,
        _ => y - size / 2.0,
    };
    Some((x0, y0, x0 + w, y0 + size))
}

/// Checks that no two level texts of `svg` overlap (by more than a pixel each way).
pub(crate) fn assert_no_overprint(name: &str, svg: &str) {
    let boxes: Vec<(String, (f64, f64, f64, f64))> = svg
        .split("<text")
        .skip(1)
        .filter_map(|part| {
            let close = part.find('>')?;
            let content = unescape(part[close + 1..part.find("</text>")?].trim());
            text_box(&part[..close], &content).map(|b| (content, b))
        })
        .collect();
    for (i, (a, p)) in boxes.iter().enumerate() {
        for (b, q) in &boxes[i + 1..] {
            let overlap_x = p.2.min(q.2) - p.0.max(q.0);
            let overlap_y = p.3.min(q.3) - p.1.max(q.1);
            assert!(
                overlap_x <= 1.0 || overlap_y <= 1.0,
                "{name}: \"{a}\" overprints \"{b}\""
            );
        }
    }
}

/// Checks that every level text of `svg` lies wholly on its canvas, by plotters' estimate
/// of its width: no name or key is clipped at an edge.
pub(crate) fn assert_inside(name: &str, svg: &str) {
    let (width, height) = canvas_size(svg);
    for part in svg.split("<text").skip(1) {
        let (Some(close), Some(end)) = (part.find('>'), part.find("</text>")) else {
            continue;
        };
        let content = unescape(part[close + 1..end].trim());
        if let Some((x0, y0, x1, y1)) = text_box(&part[..close], &content) {
            assert!(
                x0 >= 0.0 && y0 >= 0.0 && x1 <= width && y1 <= height,
                "{name}: \"{content}\" spans ({x0}, {y0})-({x1}, {y1}) off the {width}x{height} canvas"
            );
        }
    }
}

/// Checks that `svg` is a column (3.5 in) or the page (7 in) wide at 96 dpi.
pub(crate) fn assert_paper_width(name: &str, svg: &str) {
    let (width, _) = canvas_size(svg);
    assert!(width == 336.0 || width == 672.0, "{name}: {width} px wide");
}

/// Checks that `png` is the PNG of `svg` at 300 dpi, with ink on it and in its title's
/// band (text drawn, not only lines).
pub(crate) fn assert_png_of(name: &str, svg: &str, png: &[u8]) {
    use super::raster::tests::{dark_pixels, decode};
    let (w, h) = canvas_size(svg);
    let image = decode(png);
    let expected = (
        (w * 300.0 / 96.0).round() as u32,
        (h * 300.0 / 96.0).round() as u32,
    );
    assert_eq!((image.0, image.1), expected, "{name}: PNG size");
    let all = dark_pixels(&image, (0, image.0), (0, image.1));
    assert!(all > 2000, "{name}: {all} dark pixels");
    // the title's band: 6 px margin and a 10 pt line, at 300 dpi
    let title = dark_pixels(&image, (0, image.0), (15, 60));
    assert!(title > 200, "{name}: {title} dark pixels in the title");
}

/// An SVG text's content with its XML escapes read back (`&amp;` last, so that an escaped
/// escape stays as written).
fn unescape(text: &str) -> String {
    text.replace("&apos;", "'")
        .replace("&quot;", "\"")
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&amp;", "&")
}

//! A minimal SVG writer for the report's figures.
//!
//! Written by hand because the figures need text (axis labels, tick values), and plotters
//! can lay out text only with a font file loaded at run time (its `ttf` or `ab_glyph`
//! features); SVG `<text>` is laid out by the viewer, so no font has to ship or be found.

use std::fmt::Write;

/// Colours for series, distinguishable and colour-blind friendly (Okabe-Ito).
pub const PALETTE: [&str; 8] = [
    "#0072B2", "#E69F00", "#009E73", "#CC79A7", "#56B4E9", "#D55E00", "#F0E442", "#000000",
];

/// An SVG document being drawn.
pub struct Svg {
    width: f64,
    height: f64,
    body: String,
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

impl Svg {
    /// A blank white canvas of `width x height` pixels.
    pub fn new(width: f64, height: f64) -> Self {
        let mut body = String::new();
        let _ = write!(
            body,
            r#"<rect x="0" y="0" width="{width}" height="{height}" fill="white"/>"#
        );
        Svg {
            width,
            height,
            body,
        }
    }

    /// A filled rectangle.
    pub fn rect(&mut self, x: f64, y: f64, w: f64, h: f64, fill: &str) {
        let _ = write!(
            self.body,
            r#"<rect x="{x:.2}" y="{y:.2}" width="{:.2}" height="{:.2}" fill="{fill}"/>"#,
            w.max(0.0),
            h.max(0.0)
        );
    }

    /// A line segment.
    #[allow(clippy::too_many_arguments)]
    pub fn line(
        &mut self,
        x1: f64,
        y1: f64,
        x2: f64,
        y2: f64,
        stroke: &str,
        width: f64,
        dashed: bool,
    ) {
        let dash = if dashed {
            r#" stroke-dasharray="5,4""#
        } else {
            ""
        };
        let _ = write!(
            self.body,
            r#"<line x1="{x1:.2}" y1="{y1:.2}" x2="{x2:.2}" y2="{y2:.2}" stroke="{stroke}" stroke-width="{width}"{dash}/>"#
        );
    }

    /// A polyline through `points`.
    pub fn polyline(&mut self, points: &[(f64, f64)], stroke: &str, width: f64) {
        let pts: Vec<String> = points
            .iter()
            .map(|(x, y)| format!("{x:.2},{y:.2}"))
            .collect();
        let _ = write!(
            self.body,
            r#"<polyline points="{}" fill="none" stroke="{stroke}" stroke-width="{width}"/>"#,
            pts.join(" ")
        );
    }

    /// Text anchored at `anchor` (`start`, `middle`, `end`), rotated by `rotate` degrees.
    pub fn text(&mut self, x: f64, y: f64, text: &str, size: f64, anchor: &str, rotate: f64) {
        let transform = if rotate != 0.0 {
            format!(r#" transform="rotate({rotate} {x:.2} {y:.2})""#)
        } else {
            String::new()
        };
        let _ = write!(
            self.body,
            r#"<text x="{x:.2}" y="{y:.2}" font-family="sans-serif" font-size="{size}" text-anchor="{anchor}"{transform}>{}</text>"#,
            esc(text)
        );
    }

    /// The finished document.
    pub fn finish(self) -> String {
        format!(
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}">{b}</svg>
"#,
            w = self.width,
            h = self.height,
            b = self.body
        )
    }
}

/// A plotting area inside an [`Svg`] with a linear y axis.
pub struct Panel {
    /// Left edge of the plotting area.
    pub x: f64,
    /// Top edge.
    pub y: f64,
    /// Width.
    pub w: f64,
    /// Height.
    pub h: f64,
    /// Y value at the bottom.
    pub y_min: f64,
    /// Y value at the top.
    pub y_max: f64,
}

impl Panel {
    /// The pixel row of value `v`.
    pub fn py(&self, v: f64) -> f64 {
        let f = ((v - self.y_min) / (self.y_max - self.y_min)).clamp(0.0, 1.0);
        self.y + self.h * (1.0 - f)
    }

    /// Draws the axes, `ticks` horizontal grid lines with labels, a title and a y label.
    pub fn axes(
        &self,
        svg: &mut Svg,
        title: &str,
        y_label: &str,
        ticks: usize,
        fmt: impl Fn(f64) -> String,
    ) {
        for k in 0..=ticks {
            let v = self.y_min + (self.y_max - self.y_min) * k as f64 / ticks as f64;
            let py = self.py(v);
            svg.line(self.x, py, self.x + self.w, py, "#dddddd", 1.0, false);
            svg.text(self.x - 6.0, py + 4.0, &fmt(v), 11.0, "end", 0.0);
        }
        svg.line(
            self.x,
            self.y,
            self.x,
            self.y + self.h,
            "#333333",
            1.0,
            false,
        );
        svg.line(
            self.x,
            self.y + self.h,
            self.x + self.w,
            self.y + self.h,
            "#333333",
            1.0,
            false,
        );
        svg.text(
            self.x + self.w / 2.0,
            self.y - 10.0,
            title,
            14.0,
            "middle",
            0.0,
        );
        svg.text(
            self.x - 42.0,
            self.y + self.h / 2.0,
            y_label,
            12.0,
            "middle",
            -90.0,
        );
    }
}

/// A colour from white (0) to dark blue (1).
pub fn heat(f: f64) -> String {
    let f = f.clamp(0.0, 1.0);
    let r = (255.0 * (1.0 - f) + 8.0 * f) as u8;
    let g = (255.0 * (1.0 - f) + 48.0 * f) as u8;
    let b = (255.0 * (1.0 - f) + 107.0 * f) as u8;
    format!("#{r:02x}{g:02x}{b:02x}")
}

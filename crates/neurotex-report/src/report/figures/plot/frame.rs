//! A figure's frame: its title with the data's name, and where its category labels go and how
//! much room they take.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::super::FigureError;
use super::legend::{legend, legend_size, Key};
use super::{
    fit, line_height, render, text, text_width, Canvas, Drawn, Width, GREY, MARGIN, TICK, TITLE,
};

/// The height of a figure's heading: the title, and the data's name on its right or, when
/// both do not fit one line, on a line of its own.
fn heading_height(title: &str, source: &str, width: i32) -> i32 {
    let one_line = heading_fits(title, source, width);
    MARGIN + line_height(TITLE) + if one_line { 0 } else { line_height(TICK) } + 4
}

fn heading_fits(title: &str, source: &str, width: i32) -> bool {
    source.is_empty()
        || text_width(title, TITLE) + 16 + text_width(source, TICK) <= width - 2 * MARGIN
}

/// Draws the title at the top left and the data's name, in grey, at the top right (or
/// under the title when they do not fit one line).
pub(super) fn heading(canvas: &Canvas, title: &str, source: &str, width: i32) -> Drawn {
    canvas.draw(&Text::new(
        fit(title, TITLE, width - 2 * MARGIN),
        (MARGIN, MARGIN),
        text(TITLE, HPos::Left, VPos::Top),
    ))?;
    if source.is_empty() {
        return Ok(());
    }
    let grey = |h| text(TICK, h, VPos::Top).color(&GREY);
    let source_text = fit(source, TICK, width - 2 * MARGIN);
    if heading_fits(title, source, width) {
        // level with the title's baseline: the smaller text starts a little lower
        let y = MARGIN + line_height(TITLE) - line_height(TICK);
        canvas.draw(&Text::new(
            source_text,
            (width - MARGIN, y),
            grey(HPos::Right),
        ))
    } else {
        let y = MARGIN + line_height(TITLE);
        canvas.draw(&Text::new(source_text, (MARGIN, y), grey(HPos::Left)))
    }
}

/// A figure's frame: its width, the heading (title and the data's name) and the legend
/// under it, across the figure, above the body the figure draws.
pub(crate) struct Frame<'a> {
    /// The paper width.
    pub(crate) width: Width,
    /// The title.
    pub(crate) title: &'a str,
    /// The data, in a few words (`simulated rig, seed 0`, a dataset folder's name).
    pub(crate) source: &'a str,
    /// The legend; none when empty.
    pub(crate) keys: &'a [Key],
}

impl Frame<'_> {
    /// The width in pixels.
    pub(crate) fn px(&self) -> i32 {
        self.width.px()
    }

    /// The pixels above the body: the heading and the legend.
    pub(crate) fn top(&self) -> i32 {
        let legend_h = legend_size(self.keys, self.legend_w()).1;
        heading_height(self.title, self.source, self.px()) + legend_h + 4 * i32::from(legend_h > 0)
    }

    fn legend_w(&self) -> i32 {
        self.px() - 2 * MARGIN
    }

    /// Draws the frame and, through `body(root, area)`, the body of `body_h` pixels under
    /// it, full width; returns the SVG.
    pub(crate) fn render(
        &self,
        body_h: i32,
        body: impl FnOnce(&Canvas, &Canvas) -> Drawn,
    ) -> Result<String, FigureError> {
        let (width, top) = (self.px(), self.top());
        render((width, top + body_h + MARGIN), |root| {
            heading(root, self.title, self.source, width)?;
            let max_w = self.legend_w();
            let (legend_w, _) = legend_size(self.keys, max_w);
            let y = heading_height(self.title, self.source, width);
            legend(root, ((width - legend_w) / 2, y), self.keys, max_w)?;
            let area = root.clone().shrink((0, top), (width, body_h));
            body(root, &area)
        })
    }
}

/// How category labels are set under an axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Placement {
    /// One line, each label centred on its slot.
    Level,
    /// Two or three lines, the labels taking them in turn, so each has as many slots' room
    /// (cut with an ellipsis if even three are too few).
    Staggered(i32),
}

impl Placement {
    /// On as few lines (up to three) as let every label fit its room of slots of `slot`
    /// pixels.
    pub(crate) fn of(labels: &[String], slot: i32) -> Self {
        let widest = widest(labels);
        match (1..=3).find(|lines| widest + 4 <= lines * slot) {
            Some(1) => Placement::Level,
            Some(lines) => Placement::Staggered(lines),
            None => Placement::Staggered(3),
        }
    }

    /// Whether every label fits whole.
    pub(crate) fn fits(labels: &[String], slot: i32) -> bool {
        let widest = widest(labels);
        widest + 4 <= 3 * slot
    }

    fn lines(self) -> i32 {
        match self {
            Placement::Level => 1,
            Placement::Staggered(lines) => lines,
        }
    }

    /// The pixels the labels take under the axis.
    pub(crate) fn height(self) -> i32 {
        5 + self.lines() * line_height(TICK)
    }
}

/// The widest of `labels` at [`TICK`], in pixels.
pub(super) fn widest(labels: &[String]) -> i32 {
    labels
        .iter()
        .map(|l| text_width(l, TICK))
        .max()
        .unwrap_or(0)
}

/// Draws category labels below a horizontal axis at pixel row `y`, centred on the pixel
/// columns `xs`, each with a slot of `slot` pixels; returns the placement used.
pub(crate) fn category_labels(
    canvas: &Canvas,
    labels: &[String],
    xs: &[i32],
    y: i32,
    slot: i32,
) -> Result<Placement, DrawingAreaErrorKind<std::io::Error>> {
    let placement = Placement::of(labels, slot);
    let lines = placement.lines();
    for (k, (label, &x)) in labels.iter().zip(xs).enumerate() {
        let line = k as i32 % lines;
        let style = text(TICK, HPos::Center, VPos::Top);
        let at = (x, y + 5 + line * line_height(TICK));
        canvas.draw(&Text::new(fit(label, TICK, lines * slot - 4), at, style))?;
    }
    Ok(placement)
}

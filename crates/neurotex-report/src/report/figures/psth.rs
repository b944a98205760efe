//! E0: one taxel's PSTH beside the whole array's rate volume, for each example texture,
//! the PSTHs on one count scale and the volumes on one colour scale.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::plot::{
    colour_bar, colour_bar_width, fit, heat, line_height, mesh, number, text, text_width, Frame,
    Width, BEST, LABEL, MARGIN, SINGLE, TICK, X_AXIS_H, Y_AXIS_W,
};
use super::FigureError;
use crate::experiments::{E0Example, E0};

const ROW_H: i32 = 170;
const PSTH_W: i32 = 270;

/// Seconds spanned by `bins` bins of `bin_ms`.
fn seconds(bins: usize, bin_ms: usize) -> f64 {
    (bins * bin_ms) as f64 / 1000.0
}

/// Runs of equal values in `row`, as `(first bin, bin after the last, value)`.
fn runs(row: &[f64]) -> Vec<(usize, usize, f64)> {
    let mut out: Vec<(usize, usize, f64)> = Vec::new();
    for (b, &v) in row.iter().enumerate() {
        match out.last_mut() {
            Some(run) if run.2 == v => run.1 = b + 1,
            _ => out.push((b, b + 1, v)),
        }
    }
    out
}

/// The largest rate (Hz) of any volume, the colour scale's top.
fn max_rate(e: &E0) -> f64 {
    e.examples
        .iter()
        .flat_map(|x| x.volume.iter().flatten())
        .copied()
        .fold(0.0, f64::max)
}

fn volume_panel(
    area: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    ex: &E0Example,
    bin_ms: usize,
    vmax: f64,
    t: f64,
) -> Result<(), DrawingAreaErrorKind<std::io::Error>> {
    let cells = ex.volume.len().max(1);
    panel_title(area, &format!("{}: rate volume", ex.label), VOLUME_Y_AXIS)?;
    let mut chart = ChartBuilder::on(area)
        .margin(4)
        .margin_top(TITLE_H)
        .x_label_area_size(X_AXIS_H)
        .y_label_area_size(VOLUME_Y_AXIS)
        .build_cartesian_2d(0.0..t, cells as f64..0.0)?;
    mesh(&mut chart)
        .disable_mesh()
        .x_labels(6)
        .y_labels(0)
        .x_label_formatter(&|v| number(*v))
        .x_desc("time in the slide (s)")
        .y_desc("cell (row-major)")
        .draw()?;
    let step = bin_ms as f64 / 1000.0;
    // one rectangle per run of equal bins keeps a long, sparse recording's SVG small
    chart.draw_series(ex.volume.iter().enumerate().flat_map(|(c, row)| {
        runs(row).into_iter().map(move |(start, end, v)| {
            let corners = [
                (step * start as f64, c as f64),
                (step * end as f64, c as f64 + 1.0),
            ];
            Rectangle::new(corners, heat(v / vmax).filled())
        })
    }))?;
    let px_per_cell = f64::from(chart.plotting_area().dim_in_pixel().1) / cells as f64;
    let every = ((f64::from(line_height(TICK)) / px_per_cell).ceil() as usize).max(1);
    for c in (0..cells).step_by(every) {
        let (x, y) = chart.backend_coord(&(0.0, c as f64 + 0.5));
        let base = area.get_base_pixel();
        let style = text(TICK, HPos::Right, VPos::Center);
        area.draw(&Text::new(
            c.to_string(),
            (x - base.0 - 4, y - base.1),
            style,
        ))?;
    }
    Ok(())
}

fn psth_panel(
    area: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    ex: &E0Example,
    e: &E0,
    count_max: u32,
    t: f64,
) -> Result<(), DrawingAreaErrorKind<std::io::Error>> {
    let bin = e.psth_bin_ms as f64 / 1000.0;
    let top = f64::from(count_max.max(1));
    let title = format!(
        "{}: PSTH of taxel r{}c{} ({} spikes)",
        ex.label,
        e.taxel[0],
        e.taxel[1],
        ex.psth.iter().map(|&v| u64::from(v)).sum::<u64>()
    );
    panel_title(area, &title, Y_AXIS_W)?;
    let mut chart = ChartBuilder::on(area)
        .margin(4)
        .margin_top(TITLE_H)
        .x_label_area_size(X_AXIS_H)
        .y_label_area_size(Y_AXIS_W)
        // headroom keeps the top tick label clear of the title
        .build_cartesian_2d(0.0..t, 0.0..top * 1.12)?;
    mesh(&mut chart)
        .disable_x_mesh()
        .x_labels(6)
        .y_labels((count_max as usize + 1).min(5))
        .x_label_formatter(&|v| number(*v))
        .y_label_formatter(&|v| number(*v))
        .x_desc("time in the slide (s)")
        .y_desc(format!("spikes / {} ms", e.psth_bin_ms))
        .draw()?;
    // bars in a light tone under a dark outline stay legible when hundreds of bins leave
    // each bar a pixel wide
    chart.draw_series(
        ex.psth
            .iter()
            .enumerate()
            .filter(|(_, &v)| v > 0)
            .map(|(b, &v)| {
                Rectangle::new(
                    [(bin * b as f64, 0.0), (bin * (b + 1) as f64, f64::from(v))],
                    BEST.filled(),
                )
            }),
    )?;
    let mut outline = vec![(0.0, 0.0)];
    for (b, &v) in ex.psth.iter().enumerate() {
        outline.push((bin * b as f64, f64::from(v)));
        outline.push((bin * (b + 1) as f64, f64::from(v)));
    }
    outline.push((seconds(ex.psth.len(), e.psth_bin_ms), 0.0));
    chart.draw_series(LineSeries::new(outline, SINGLE.stroke_width(1)))?;
    Ok(())
}

/// Room for a panel's title above its plot.
const TITLE_H: i32 = 20;
/// The volume's cell numbers and axis description.
const VOLUME_Y_AXIS: i32 = 40;

/// A panel's title, centred over its plot (right of `left` pixels of y axis).
fn panel_title(
    area: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    title: &str,
    left: i32,
) -> Result<(), DrawingAreaErrorKind<std::io::Error>> {
    let w = area.dim_in_pixel().0 as i32;
    let style = text(LABEL, HPos::Center, VPos::Top);
    let title = fit(title, LABEL, w - 8);
    // centred over the plot, but kept on the panel
    let centre = ((left + w) / 2).min(w - 4 - text_width(&title, LABEL) / 2);
    area.draw(&Text::new(title, (centre, 4), style))
}

/// E0: per example texture, the PSTH of the chosen taxel and the rate volume of every cell.
pub(crate) fn e0(e: &E0, source: &str) -> Result<String, FigureError> {
    let rows = e.examples.len().max(1) as i32;
    let count_max = e
        .examples
        .iter()
        .flat_map(|x| x.psth.iter())
        .copied()
        .max()
        .unwrap_or(0);
    let vmax = max_rate(e);
    // one time axis for every panel, so the examples compare bin by bin
    let bins = e
        .examples
        .iter()
        .map(|x| x.psth.len())
        .max()
        .unwrap_or(0)
        .max(1);
    let t = seconds(bins, e.psth_bin_ms);
    let title = format!("E0: PSTH and rate volume at {} mm/s", e.speed);
    let frame = Frame {
        width: Width::Page,
        title: &title,
        source,
        keys: &[],
    };
    let bar_w = colour_bar_width(vmax);
    let volume_w = frame.px() - PSTH_W - 8 - bar_w - MARGIN - 8;
    frame.render(ROW_H * rows, |_, body| {
        for (k, ex) in e.examples.iter().enumerate() {
            let y = ROW_H * k as i32;
            let left = body.clone().shrink((0, y), (PSTH_W, ROW_H));
            psth_panel(&left, ex, e, count_max, t)?;
            let right = body.clone().shrink((PSTH_W + 8, y), (volume_w, ROW_H));
            volume_panel(
                &right,
                ex,
                e.psth_bin_ms,
                if vmax > 0.0 { vmax } else { 1.0 },
                t,
            )?;
        }
        let bar_x = PSTH_W + 8 + volume_w + 8;
        colour_bar(
            body,
            (bar_x, TITLE_H + 4),
            ROW_H * rows - TITLE_H - X_AXIS_H - 8,
            vmax,
            "spike rate (Hz)",
        )
    })
}

/// E0's caption, from the data: the taxel, the number of cells, the bin width and the slide
/// length shown.
pub(crate) fn e0_caption(e: &E0) -> String {
    let labels: Vec<&str> = e.examples.iter().map(|x| x.label.as_str()).collect();
    let cells = e.examples.first().map_or(0, |x| x.volume.len());
    let bins = e
        .examples
        .first()
        .and_then(|x| x.volume.first())
        .map_or(0, Vec::len);
    format!(
        "Taxel r{}c{} at {} mm/s, first recording of {}: left, the taxel's PSTH (spikes per {} ms bin, one count scale; a last, shorter bin is kept); right, the rate volume of all {} cells of the array (rows, in row-major order) over {} bins of {} ms ({} s of the slide; a last, shorter bin is dropped), on one colour scale in Hz; all panels share one time axis. The paper: the volumes differ more than the PSTHs.",
        e.taxel[0],
        e.taxel[1],
        e.speed,
        labels.join(" and "),
        e.psth_bin_ms,
        cells,
        bins,
        e.psth_bin_ms,
        number(seconds(bins, e.psth_bin_ms)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_join_equal_neighbours() {
        assert_eq!(
            runs(&[0.0, 0.0, 5.0, 0.0]),
            vec![(0, 2, 0.0), (2, 3, 5.0), (3, 4, 0.0)]
        );
        assert!(runs(&[]).is_empty());
    }
}

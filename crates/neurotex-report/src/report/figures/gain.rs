//! E7: the gain sweep, as firing rate against gain and as ISI distributions per gain.

use plotters::prelude::*;

use super::accuracy::plot_height;
use super::plot::{
    legend_size, line_chart, line_with_markers, mesh, multiples, number, panel_chart, series,
    vline, Frame, Key, Multiples, Swatch, Width, GREY, LIGHT, MARGIN, X_AXIS_H,
};
use super::FigureError;
use crate::experiments::E7;
use crate::report::paper::PAPER_GAIN;

/// The classes recorded at the sweep's speed, by index: a class with no encoded taxel time
/// at any gain was not recorded there and is left out, rather than drawn as silent.
fn recorded(e: &E7) -> Vec<usize> {
    (0..e.sweep.labels.len())
        .filter(|&l| {
            e.sweep
                .taxel_seconds
                .iter()
                .any(|row| row.get(l).is_some_and(|&t| t > 0.0))
        })
        .collect()
}

/// One legend entry per recorded class, lines with markers or plain lines.
fn class_keys(e: &E7, shown: &[usize], markers: bool) -> Vec<Key> {
    shown
        .iter()
        .enumerate()
        .map(|(k, &l)| {
            let (colour, dashed) = series(k);
            let swatch = match (markers, dashed) {
                (true, false) => Swatch::Points(colour),
                (true, true) => Swatch::DashedPoints(colour),
                (false, false) => Swatch::Line(colour),
                (false, true) => Swatch::DashedLine(colour),
            };
            Key::new(e.sweep.labels[l].as_str(), swatch)
        })
        .collect()
}

/// E7: mean firing rate per taxel against gain, one line per class.
pub(crate) fn e7_rate(e: &E7, source: &str) -> Result<String, FigureError> {
    let gains = &e.sweep.gains;
    let shown = recorded(e);
    let mut keys = class_keys(e, &shown, true);
    keys.push(Key::new(
        format!("paper: G = {PAPER_GAIN}"),
        Swatch::Dashed(GREY),
    ));
    // a column, unless the classes' legend would take more room than the plot there
    let width = if legend_size(&keys, Width::Column.px() - 2 * MARGIN).1 > 4 * 15 {
        Width::Page
    } else {
        Width::Column
    };
    let lo = gains
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min)
        .min(PAPER_GAIN);
    let hi = gains
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max)
        .max(PAPER_GAIN);
    let top = e
        .rate_hz
        .iter()
        .flatten()
        .copied()
        .fold(0.0, f64::max)
        .max(1.0)
        * 1.08;
    let title = format!("E7: firing rate against gain at {} mm/s", e.speed);
    let frame = Frame {
        width,
        title: &title,
        source,
        keys: &keys,
    };
    frame.render(plot_height(width) + X_AXIS_H, |_, area| {
        let mut chart = line_chart(area, lo - 0.5..hi + 0.5, 0.0..top)?;
        mesh(&mut chart)
            .x_labels(10)
            .y_labels(8)
            .x_label_formatter(&|v| number(*v))
            .y_label_formatter(&|v| number(*v))
            .x_desc("gain G")
            .y_desc("rate per taxel (Hz)")
            .draw()?;
        vline(&mut chart, PAPER_GAIN, GREY, 6)?;
        for (k, &l) in shown.iter().enumerate() {
            let points: Vec<(f64, f64)> = gains
                .iter()
                .zip(&e.rate_hz)
                .filter_map(|(&g, rates)| rates.get(l).map(|&r| (g, r)))
                .collect();
            let (colour, dashed) = series(k);
            line_with_markers(&mut chart, &points, colour, dashed)?;
        }
        Ok(())
    })
}

/// The cumulative share (%) of ISIs up to each bin's upper edge, with the overflow bin last;
/// `None` when the histogram is empty.
fn cumulative(hist: &[u64]) -> Option<Vec<f64>> {
    let total: u64 = hist.iter().sum();
    (total > 0).then(|| {
        let mut acc = 0;
        hist.iter()
            .map(|&c| {
                acc += c;
                100.0 * acc as f64 / total as f64
            })
            .collect()
    })
}

/// Bins of the sweep's ISI histograms (the last one holds the longer intervals).
fn histogram_bins(e: &E7) -> usize {
    let lengths = e.sweep.counts.iter().flatten().map(Vec::len);
    lengths.max().unwrap_or(1).max(1)
}

/// E7: the cumulative ISI distribution per gain, one panel per gain on one scale, the ISIs
/// beyond the histogram's range shown in a labelled band at the right.
pub(crate) fn e7_isi(e: &E7, source: &str) -> Result<String, FigureError> {
    let bins = histogram_bins(e);
    let bin = f64::from(e.sweep.bin_ms.max(1));
    let range = bin * (bins - 1) as f64;
    let band = (range / 8.0).max(bin);
    let shown = recorded(e);
    let mut keys = class_keys(e, &shown, false);
    keys.push(Key::new(
        format!("ISIs of {} ms or more", number(range)),
        Swatch::Band(LIGHT),
    ));
    let layout = Multiples {
        n: e.sweep.gains.len(),
        aspect: 0.6,
        title: &format!("E7: ISI distribution per gain at {} mm/s", e.speed),
        source,
        x_desc: "inter-spike interval (ms)",
        y_desc: "ISIs up to this length (%)",
        keys: &keys,
    };
    multiples(&layout, |g, area| {
        let gain = e.sweep.gains[g];
        let lines: Vec<Option<Vec<f64>>> = shown
            .iter()
            .map(|&l| e.sweep.counts[g].get(l).and_then(|h| cumulative(h)))
            .collect();
        let silent = lines.iter().filter(|c| c.is_none()).count();
        let mut title = format!("G = {}", number(gain));
        if gain == PAPER_GAIN {
            title += " (paper)";
        }
        if silent > 0 {
            title += &format!(", {silent} silent");
        }
        let mut chart = panel_chart(area, &title, 0.0..range + band, 0.0..100.0)?;
        chart.draw_series([Rectangle::new(
            [(range, 0.0), (range + band, 100.0)],
            LIGHT.filled(),
        )])?;
        mesh(&mut chart)
            .x_labels(4)
            .y_labels(3)
            .x_label_formatter(&|v| number(*v))
            .y_label_formatter(&|v| number(*v))
            .draw()?;
        for (k, cum) in lines.iter().enumerate() {
            let Some(cum) = cum else { continue };
            let mut points = vec![(0.0, 0.0)];
            points.extend(
                cum.iter()
                    .take(bins - 1)
                    .enumerate()
                    .map(|(b, &c)| (bin * (b + 1) as f64, c)),
            );
            points.push((range + band, 100.0));
            let (colour, dashed) = series(k);
            let style = colour.stroke_width(2);
            if dashed {
                chart.draw_series(DashedLineSeries::new(points, 7, 4, style))?;
            } else {
                chart.draw_series(LineSeries::new(points, style))?;
            }
        }
        Ok(())
    })
}

/// The classes of the dataset not recorded at the sweep's speed, for the captions.
fn absent_note(e: &E7) -> String {
    let shown = recorded(e);
    let absent: Vec<&str> = (0..e.sweep.labels.len())
        .filter(|l| !shown.contains(l))
        .map(|l| e.sweep.labels[l].as_str())
        .collect();
    if absent.is_empty() {
        String::new()
    } else {
        format!(
            " Not recorded at {} mm/s, so not drawn: {}.",
            e.speed,
            absent.join(", ")
        )
    }
}

/// E7's caption for the rate figure.
pub(crate) fn e7_rate_caption(e: &E7) -> String {
    format!(
        "Mean firing rate per taxel (spikes per taxel-second of the slide) against the gain G, one line per class, at {} mm/s; the dashed line marks the paper's choice, G = {}.{}",
        e.speed,
        PAPER_GAIN,
        absent_note(e)
    )
}

/// E7's caption for the ISI figure.
pub(crate) fn e7_isi_caption(e: &E7) -> String {
    let bins = histogram_bins(e);
    let range = e.sweep.bin_ms as usize * (bins - 1);
    format!(
        "Cumulative distribution of inter-spike intervals at {} mm/s, pooled over trials and taxels, one panel per gain on one scale and one line per class ({} ms bins). The grey band on the right holds the ISIs of {} ms or more: each line's rise across it is their share. A class with fewer than two spikes in every taxel has no ISI and no line; the panel's title counts such silent classes and marks the paper's choice of G.{}",
        e.speed,
        e.sweep.bin_ms,
        range,
        absent_note(e)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cumulative_ends_at_100_and_empty_is_none() {
        assert_eq!(cumulative(&[1, 1, 2]), Some(vec![25.0, 50.0, 100.0]));
        assert_eq!(cumulative(&[0, 0]), None);
    }
}

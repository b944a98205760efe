//! Every figure on two designs: the small simulated one of the golden test (2 speeds,
//! 4 classes) and a hand-built FabricSlide-shaped one (12 signed speeds, 7 long class
//! names, 16 gains), checked for well-formed SVG that stays on its canvas.

use std::collections::BTreeMap;

use super::*;
use crate::experiments::{
    E0Example, E1Speed, E4Speed, E5Speed, E6Speed, E8Speed, IsiSweep, TaxelDiagnostics,
    TaxelResponse, E0, E2, E3, E7,
};
use crate::report::paper::PAPER;
use crate::values::{BySpeed, Speed};

/// The golden test's small design, as stored (accuracies rounded to 1e-6).
pub(crate) fn small() -> Results {
    let text = include_str!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../neurotex/tests/data/golden_small_design.json"
    ));
    serde_json::from_str(text).expect("golden results parse")
}

/// A deterministic value in 0..1 for index `i` (no randomness needed, just variety).
fn wobble(i: usize) -> f64 {
    ((i * 37 + 11) % 100) as f64 / 100.0
}

/// A FabricSlide-shaped result: 12 signed speeds, 7 classes with long names, 16 gains.
pub(crate) fn wide() -> Results {
    let speeds: Vec<Speed> = [-150, -120, -100, -50, -20, -10, 10, 20, 50, 100, 120, 150]
        .iter()
        .map(|&s| Speed::of(f64::from(s)))
        .collect();
    let labels: Vec<String> = [
        "BeigeCotton",
        "BrownCotton",
        "Canvas",
        "DenimFlex",
        "Denim",
        "Linen",
        "WovenFabric",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let by = |f: &dyn Fn(usize) -> f64| -> Vec<f64> { (0..speeds.len()).map(f).collect() };
    let acc = by(&|i| 0.3 + 0.5 * wobble(i));
    let e1: BySpeed<E1Speed> = speeds
        .iter()
        .enumerate()
        .map(|(i, &s)| {
            (
                s,
                E1Speed {
                    taxel_mean: acc[i] * 0.6,
                    taxel_best: acc[i] * 0.9,
                    taxel_best_cell: "r1c0".into(),
                    glcm3d: acc[i],
                    glcm3d_std: 0.03,
                    encodings: 8,
                    n: 69,
                    // FabricSlide records 5 of its 7 fabrics at the positive speeds
                    classes: if s.mm_s() > 0.0 { 5 } else { 7 },
                    chance: if s.mm_s() > 0.0 { 0.2 } else { 1.0 / 7.0 },
                    majority: if s.mm_s() > 0.0 { 0.22 } else { 0.16 },
                    taxel_mean_responsive: Some(acc[i] * 0.8),
                    glcm3d_interval: interval(acc[i]),
                    taxel_mean_interval: interval(acc[i] * 0.6),
                    glcm3d_vs_taxel: comparison(acc[i] * 0.4),
                },
            )
        })
        .collect();
    let e4 = speeds
        .iter()
        .enumerate()
        .map(|(i, &s)| {
            (
                s,
                E4Speed {
                    taxel_mean: acc[i] * 0.6,
                    glcm2d: acc[i] * 0.7,
                    glcm3d: acc[i],
                    glcm2d_interval: interval(acc[i] * 0.7),
                    taxel_vs_glcm2d: comparison(-acc[i] * 0.1),
                    glcm3d_vs_glcm2d: comparison(acc[i] * 0.3),
                },
            )
        })
        .collect();
    let fractions: Vec<f64> = (1..=10).map(|k| k as f64 / 10.0).collect();
    let e5 = speeds
        .iter()
        .enumerate()
        .map(|(i, &s)| {
            let glcm3d: Vec<Option<f64>> = fractions
                .iter()
                .map(|&p| (p > 0.1 || i > 3).then_some(acc[i] * (0.4 + 0.6 * p)))
                .collect();
            (
                s,
                E5Speed {
                    fractions: fractions.clone(),
                    glcm3d_interval: glcm3d.iter().map(|a| a.map(interval)).collect(),
                    glcm3d,
                    taxel_full: acc[i] * 0.6,
                    taxel_full_interval: Some(interval(acc[i] * 0.6)),
                    first_match: Some(0.3),
                    longest_vs_shortest: None,
                },
            )
        })
        .collect();
    let e5c = speeds
        .iter()
        .enumerate()
        .map(|(i, &s)| {
            let bins = 5 + 3 * i;
            let times_s: Vec<f64> = (1..=bins).map(|b| 0.2 * b as f64).collect();
            let rise = |b: usize| (b as f64 / bins as f64).min(1.0);
            (
                s,
                crate::experiments::E5CausalSpeed {
                    calibration: crate::causal::ConditioningCalibration {
                        conditioning: crate::signal::CausalConditioning {
                            offsets: vec![0.0; 16],
                            scale: 1234.5,
                        },
                        recordings: 69,
                        median_duration_ms: 200 * bins,
                        rest_spread: 0.0,
                    },
                    n: 69,
                    chance: if s.mm_s() > 0.0 { 0.2 } else { 1.0 / 7.0 },
                    median_slide_s: 0.2 * bins as f64,
                    accuracy: (1..=bins).map(|b| acc[i] * (0.3 + 0.6 * rise(b))).collect(),
                    sliding: (1..=bins).map(|b| 1.0 - 0.5 * rise(b).powi(8)).collect(),
                    fractions: e5_fraction_rows(&fractions, 0.2 * bins as f64, acc[i]),
                    whole: acc[i] * 0.9,
                    whole_interval: interval(acc[i] * 0.9),
                    offline: acc[i],
                    offline_vs_causal: comparison(acc[i] * 0.1),
                    decision: crate::experiments::TimeToDecision {
                        rule: crate::causal::DecisionRule::default(),
                        episodes: 69,
                        decided: 50,
                        never_share: 19.0 / 69.0,
                        accuracy: Some(0.8),
                        quartiles_s: Some([0.6, 0.2 * (bins / 2).max(3) as f64, 0.2 * bins as f64]),
                        decided_by: (1..=bins).map(|b| 50.0 / 69.0 * rise(b)).collect(),
                    },
                    times_s,
                },
            )
        })
        .collect();
    let e6 = speeds
        .iter()
        .enumerate()
        .map(|(i, &s)| {
            let train = speeds.iter().copied().filter(|&t| t != s).collect();
            (
                s,
                E6Speed {
                    train,
                    chance: if s.mm_s() > 0.0 { 0.2 } else { 1.0 / 7.0 },
                    taxel_mean: 0.3,
                    encodings: 1,
                    glcm3d: acc[i] * 0.8,
                    taxel_mean_interval: interval(0.3),
                    glcm3d_interval: interval(acc[i] * 0.8),
                    glcm3d_vs_taxel: comparison(acc[i] * 0.8 - 0.3),
                },
            )
        })
        .collect();
    let ks = vec![1, 3, 5, 7, 9];
    let e8 = speeds
        .iter()
        .enumerate()
        .map(|(i, &s)| {
            let shift = |d: f64| -> Vec<f64> {
                ks.iter()
                    .map(|&k| (acc[i] * d - 0.01 * k as f64).max(0.0))
                    .collect()
            };
            (
                s,
                E8Speed {
                    k: ks.clone(),
                    encodings: 1,
                    taxel_mean_interval: shift(0.6).into_iter().map(interval).collect(),
                    glcm3d_interval: shift(1.0).into_iter().map(interval).collect(),
                    taxel_mean: shift(0.6),
                    glcm3d: shift(1.0),
                    glcm3d_vs_taxel: Vec::new(),
                },
            )
        })
        .collect();
    let n = labels.len();
    let confusion = |strength: usize| -> Vec<Vec<usize>> {
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| if i == j { strength } else { (i + 2 * j) % 5 })
                    .collect()
            })
            .collect()
    };
    let gains: Vec<f64> = (5..=20).map(f64::from).collect();
    let bins = 61;
    let counts = gains
        .iter()
        .enumerate()
        .map(|(g, _)| {
            (0..n)
                .map(|l| {
                    if l == 3 && g < 8 {
                        return vec![0; bins];
                    }
                    (0..bins)
                        .map(|b| {
                            if b == bins - 1 {
                                400
                            } else {
                                ((b * (l + 1) + g) % 13) as u64
                            }
                        })
                        .collect()
                })
                .collect()
        })
        .collect();
    let rate_hz: Vec<Vec<f64>> = gains
        .iter()
        .map(|g| {
            (0..n)
                .map(|l| (g - 5.0) * 0.4 * (l as f64 + 1.0) / n as f64)
                .collect()
        })
        .collect();
    let cells = 16;
    let example = |label: &str, phase: usize| E0Example {
        label: label.into(),
        file: format!("{label}.csv"),
        psth: (0..28).map(|b| ((b + phase) % 4) as u32 / 3).collect(),
        volume: (0..cells)
            .map(|c| {
                (0..27)
                    .map(|b| 5.0 * ((b + c + phase) % 3) as f64)
                    .collect()
            })
            .collect(),
    };
    Results {
        speeds: speeds.clone(),
        labels: labels.clone(),
        recordings: 962,
        resampled: 962,
        flat: 0,
        taxels: TaxelDiagnostics {
            ceiling_hz: 63.0,
            taxels: (0..16)
                .map(|i| TaxelResponse {
                    taxel: format!("r{}c{}", i / 4, i % 4),
                    silent_share: if i == 0 { 0.98 } else { 0.3 },
                    saturated_share: 0.0,
                })
                .collect(),
        },
        e0: Some(E0 {
            speed: Speed::of(10.0),
            taxel: [1, 1],
            psth_bin_ms: 200,
            examples: vec![example("BeigeCotton", 0), example("BrownCotton", 1)],
        }),
        e1,
        e2: Some(E2 {
            speed: Speed::of(10.0),
            labels: labels.clone(),
            taxel: confusion(30),
            glcm3d: confusion(60),
            glcm3d_vs_taxel_by_class: Vec::new(),
        }),
        e3: Some(E3 {
            speed: Speed::of(10.0),
            repeats: 10,
            n: (2..=16).collect(),
            mean: (2..=16).map(|k| 0.7 - 0.01 * k as f64).collect(),
            std: (2..=16).map(|k| 0.02 + 0.002 * k as f64).collect(),
            interval: (2..=16).map(|k| interval(0.7 - 0.01 * k as f64)).collect(),
            glcm3d: 0.71,
            taxel_mean: 0.36,
            unperturbed_vs_moved: Vec::new(),
        }),
        e4,
        e5,
        e5c,
        e6,
        e7: Some(E7 {
            speed: Speed::of(10.0),
            sweep: IsiSweep {
                gains: gains.clone(),
                labels: labels.clone(),
                bin_ms: 5,
                counts,
                spikes: vec![vec![0; n]; gains.len()],
                taxel_seconds: vec![vec![1.0; n]; gains.len()],
            },
            rate_hz,
            median_isi_ms: vec![vec![None; n]; gains.len()],
        }),
        e8,
        e9: None,
        encoder_sensitivity: None,
        across_seeds: None,
        predictions: Vec::new(),
        gain_calibration: None,
        provenance: None,
        skipped: BTreeMap::new(),
        timing_s: BTreeMap::new(),
    }
}

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
            let content = part[close + 1..part.find("</text>")?]
                .trim()
                .replace("&apos;", "'")
                .replace("&quot;", "\"")
                .replace("&lt;", "<")
                .replace("&gt;", ">")
                .replace("&amp;", "&");
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
        let content = part[close + 1..end]
            .trim()
            .replace("&apos;", "'")
            .replace("&quot;", "\"")
            .replace("&lt;", "<")
            .replace("&gt;", ">")
            .replace("&amp;", "&");
        if let Some((x0, y0, x1, y1)) = text_box(&part[..close], &content) {
            assert!(
                x0 >= 0.0 && y0 >= 0.0 && x1 <= width && y1 <= height,
                "{name}: \"{content}\" spans ({x0}, {y0})-({x1}, {y1}) off the {width}x{height} canvas"
            );
        }
    }
}

/// The data's name the tests draw on every figure.
const SOURCE: &str = "test design";

fn check_all(r: &Results, paper: Option<&Paper>) -> Vec<&'static str> {
    let figures = all(r, paper, SOURCE);
    for (name, svg) in &figures {
        let svg = svg.as_ref().unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_well_formed(name, svg);
        assert_no_overprint(name, svg);
        assert_inside(name, svg);
        assert_paper_width(name, svg);
        // Over several datasets, the figures of the first name it alone.
        let first = r.across_seeds.as_ref().map(|a| a.seeds[0]);
        let source = match first {
            Some(seed) if *name != super::file::SEEDS => format!("simulated rig, seed {seed}"),
            _ => SOURCE.to_string(),
        };
        assert!(svg.contains(&source), "{name}: the data's name");
        if let Some(dump) = std::env::var_os("NEUROTEX_DUMP_FIGURES") {
            std::fs::write(std::path::Path::new(&dump).join(name), svg).unwrap();
        }
    }
    figures.iter().map(|(n, _)| *n).collect()
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

#[test]
fn every_figure_is_also_a_png_of_the_same_figure() {
    for (r, paper) in [(small(), Some(&PAPER)), (wide(), None)] {
        for (name, svg) in all(&r, paper, SOURCE) {
            let svg = svg.unwrap();
            let files = svg_and_png(name, svg.clone()).unwrap();
            assert_eq!(files[0].0, name);
            assert_eq!(files[1].0, name.replace(".svg", ".png"));
            assert_png_of(name, &svg, &files[1].1);
        }
    }
}

#[test]
fn every_figure_is_well_formed_on_both_designs() {
    let names = check_all(&small(), Some(&PAPER));
    assert_eq!(names.len(), 12, "{names:?}");
    assert_eq!(check_all(&wide(), None).len(), 12);
}

#[test]
fn e1_shows_paper_bars_only_when_comparable() {
    let r = small();
    let with = accuracy::e1(&r, Some(&PAPER), SOURCE).unwrap();
    let without = accuracy::e1(&r, None, SOURCE).unwrap();
    assert!(with.contains("paper: 3D-GLCM") && !without.contains("paper: 3D-GLCM"));
    assert_well_formed("e1", &accuracy::e1(&wide(), None, SOURCE).unwrap());
}

#[test]
fn e2_labels_every_class_on_both_axes() {
    let r = wide();
    let svg = confusion::e2(r.e2.as_ref().unwrap(), SOURCE).unwrap();
    assert_well_formed("e2", &svg);
    for label in &r.labels {
        assert!(
            svg.matches(&format!(">\n{label}\n<")).count()
                + svg.matches(&format!(">{label}<")).count()
                >= 3,
            "{label}"
        );
    }
    // long names do not fit a cell level: the columns' are staggered, never turned
    for part in svg.split("<text").skip(1) {
        if part.contains("rotate(") {
            assert!(r
                .labels
                .iter()
                .all(|l| !part.contains(&format!(">\n{l}\n<"))));
        }
    }
    assert_well_formed(
        "e2 small",
        &confusion::e2(small().e2.as_ref().unwrap(), SOURCE).unwrap(),
    );
}

#[test]
fn e3_e5_e8_draw_on_both_designs() {
    for r in [small(), wide()] {
        assert_well_formed(
            "e3",
            &perturbation::e3(r.e3.as_ref().unwrap(), r.e2.as_ref(), chance(&r), SOURCE).unwrap(),
        );
        assert_well_formed("e5", &recognition::e5(&r, Some(&PAPER), SOURCE).unwrap());
        assert_well_formed("e8", &neighbours::e8(&r, SOURCE).unwrap());
        assert_well_formed("e4", &accuracy::e4(&r, None, SOURCE).unwrap());
        assert_well_formed("e6", &accuracy::e6(&r, Some(&PAPER), SOURCE).unwrap());
    }
}

#[test]
fn e4_e5_e6_e8_draw_chance_per_speed_from_the_classes_recorded_there() {
    let figures = |r: &Results| -> Vec<(&str, String)> {
        vec![
            ("e4", accuracy::e4(r, None, SOURCE).unwrap()),
            ("e5", recognition::e5(r, None, SOURCE).unwrap()),
            ("e6", accuracy::e6(r, None, SOURCE).unwrap()),
            ("e8", neighbours::e8(r, SOURCE).unwrap()),
        ]
    };
    // FabricSlide's design: 5 classes at the positive speeds, 7 at the negative ones
    let wide = wide();
    for (name, svg) in figures(&wide) {
        assert!(svg.contains("chance at each speed"), "{name}");
        assert!(!svg.contains("chance, all classes"), "{name}");
        if let Some(dump) = std::env::var_os("NEUROTEX_DUMP_FIGURES") {
            let path = std::path::Path::new(&dump).join(format!("wide_{name}.svg"));
            std::fs::write(path, &svg).unwrap();
        }
    }
    let captions = [
        accuracy::e4_caption(&wide, None),
        accuracy::e6_caption(&wide, None),
        recognition::e5_caption(&wide, None),
        neighbours::e8_caption(&wide),
    ];
    assert!(captions
        .iter()
        .all(|c| c.contains("chance there") || c.contains("chance at that speed")));
    // the same number of classes everywhere: one value in the key
    for (name, svg) in figures(&small()) {
        assert!(svg.contains("chance ("), "{name}");
    }
    assert!(!neighbours::e8_caption(&small()).contains("% at"));
    // without E1, E6 (each speed held out) knows the classes at each speed
    let mut without_e1 = small();
    without_e1.e1 = BySpeed::new();
    for (name, svg) in figures(&without_e1) {
        assert!(svg.contains("chance (25 %)"), "{name}");
    }
    // without either (E6 written before it kept its chance) the classes per speed are
    // unknown: one line for all classes
    without_e1.e6.values_mut().for_each(|e| e.chance = 0.0);
    for (name, svg) in figures(&without_e1) {
        assert!(svg.contains("chance, all classes"), "{name}");
    }
}

#[test]
fn e7_labels_the_overflow_band_and_notes_silent_classes() {
    let r = wide();
    let e7 = r.e7.as_ref().unwrap();
    let isi = gain::e7_isi(e7, SOURCE).unwrap();
    assert_well_formed("e7 isi", &isi);
    assert!(isi.contains("ISIs of 300 ms or more"));
    assert!(
        isi.contains("G = 5, 1 silent") && isi.contains("G = 8 (paper), 1 silent"),
        "{isi}"
    );
    assert_well_formed("e7 rate", &gain::e7_rate(e7, SOURCE).unwrap());
    let small = small();
    assert_well_formed(
        "e7 small",
        &gain::e7_isi(small.e7.as_ref().unwrap(), SOURCE).unwrap(),
    );
}

#[test]
fn e0_caption_comes_from_the_data() {
    let r = wide();
    let e0 = r.e0.as_ref().unwrap();
    assert_well_formed("e0", &psth::e0(e0, SOURCE).unwrap());
    let caption = e0_caption(e0);
    assert!(
        caption.contains("all 16 cells") && caption.contains("27 bins of 200 ms"),
        "{caption}"
    );
    let mut fewer = e0.clone();
    fewer.psth_bin_ms = 100;
    for x in &mut fewer.examples {
        x.volume.truncate(6);
    }
    let caption = e0_caption(&fewer);
    assert!(
        caption.contains("all 6 cells") && caption.contains("100 ms"),
        "{caption}"
    );
    assert_well_formed(
        "e0 small",
        &psth::e0(small().e0.as_ref().unwrap(), SOURCE).unwrap(),
    );
}

/// The same checks on a written report's figures and their PNGs, for reports of real data:
/// `NEUROTEX_FIGURES=report/figures cargo test -p neurotex --lib -- --ignored figures_in`.
#[test]
#[ignore]
fn figures_in_a_folder_are_well_formed() {
    let dir = std::env::var("NEUROTEX_FIGURES").expect("NEUROTEX_FIGURES names a folder");
    let mut checked = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "svg") {
            let svg = std::fs::read_to_string(&path).unwrap();
            let name = path.display().to_string();
            assert_well_formed(&name, &svg);
            assert_no_overprint(&name, &svg);
            assert_inside(&name, &svg);
            assert_paper_width(&name, &svg);
            let png = std::fs::read(path.with_extension("png")).unwrap();
            assert_png_of(&name, &svg, &png);
            checked += 1;
        }
    }
    assert!(checked > 0, "no SVG in {dir}");
}

#[test]
fn thirty_classes_still_lay_out() {
    let labels: Vec<String> = (0..30).map(|i| format!("texture number {i}")).collect();
    let m: Vec<Vec<usize>> = (0..30)
        .map(|i| {
            (0..30)
                .map(|j| usize::from(i == j) * 9 + (i + j) % 2)
                .collect()
        })
        .collect();
    let e2 = E2 {
        speed: Speed::of(5.0),
        labels: labels.clone(),
        taxel: m.clone(),
        glcm3d: m,
        glcm3d_vs_taxel_by_class: Vec::new(),
    };
    let svg = confusion::e2(&e2, SOURCE).unwrap();
    assert_well_formed("e2, 30 classes", &svg);
    assert_no_overprint("e2, 30 classes", &svg);
    assert!(
        !e2_caption(&e2).contains("a 0 is"),
        "no numbers in 20 px cells"
    );
    let mut r = wide();
    let e7 = r.e7.as_mut().unwrap();
    e7.sweep.labels = labels;
    for per_gain in &mut e7.sweep.counts {
        per_gain.resize(30, vec![1; 61]);
    }
    for row in e7.sweep.taxel_seconds.iter_mut().chain(&mut e7.rate_hz) {
        row.resize(30, 1.0);
    }
    for (name, svg) in [
        ("e7 isi", gain::e7_isi(e7, SOURCE)),
        ("e7 rate", gain::e7_rate(e7, SOURCE)),
    ] {
        let svg = svg.unwrap();
        assert_well_formed(name, &svg);
        assert_no_overprint(name, &svg);
    }
}

/// E5c's rows at E5's shares of a slide of `slide_s`.
fn e5_fraction_rows(
    fractions: &[f64],
    slide_s: f64,
    a: f64,
) -> Vec<crate::experiments::E5cFraction> {
    fractions
        .iter()
        .map(|&p| crate::experiments::E5cFraction {
            fraction: p,
            time_s: p * slide_s,
            causal: Some(a * (0.3 + 0.6 * p)),
            causal_interval: Some(interval(a * (0.3 + 0.6 * p))),
            offline: Some(a * (0.4 + 0.6 * p)),
            offline_interval: Some(interval(a * (0.4 + 0.6 * p))),
        })
        .collect()
}

/// A hand-made 95 % interval of ±5 points around `a`.
fn interval(a: f64) -> crate::classify::Interval {
    crate::classify::Interval {
        estimate: a,
        lower: (a - 0.05).max(0.0),
        upper: (a + 0.05).min(1.0),
        level: 0.95,
        method: crate::classify::IntervalMethod::PercentileBootstrap {
            n: 69,
            resamples: 2000,
            seed: 0,
        },
    }
}

/// A hand-made comparison with difference `d` and an interval of ±8 points.
fn comparison(d: f64) -> crate::experiments::Comparison {
    let (lower, upper) = (d - 0.08, d + 0.08);
    let verdict = if lower > 0.0 {
        crate::classify::PairedVerdict::Supported
    } else if upper < 0.0 {
        crate::classify::PairedVerdict::Contradicted
    } else {
        crate::classify::PairedVerdict::NotShown
    };
    crate::experiments::Comparison {
        first: "a".into(),
        second: "b".into(),
        difference: d,
        lower,
        upper,
        verdict,
        recordings: 69,
    }
}

#[test]
fn across_seeds_draws_every_dataset_and_only_with_several() {
    for r in [small(), wide()] {
        assert!(
            super::seeds::across_seeds(&r, SOURCE).is_none(),
            "one dataset: no figure"
        );
        let mut other = r.clone();
        for e in other
            .e1
            .values()
            .cloned()
            .collect::<Vec<_>>()
            .iter()
            .zip(r.speeds.iter())
        {
            let mut e1 = e.0.clone();
            e1.glcm3d = (e1.glcm3d - 0.05).max(0.0);
            other.e1.insert(*e.1, e1);
        }
        let runs = [(0, &r), (1, &other), (2, &r)];
        let mut with = r.clone();
        with.across_seeds = Some(crate::experiments::across_seeds(&runs).unwrap());
        let svg = super::seeds::across_seeds(&with, SOURCE).unwrap().unwrap();
        assert_well_formed("across_seeds", &svg);
        assert_no_overprint("across_seeds", &svg);
        // Three dots per method and group (E1 and E6 at every speed), and one marker per
        // method in the legend.
        let groups = r.e1.len() + r.e6.len();
        assert_eq!(svg.matches("<circle").count(), 3 * 2 * groups + 2, "dots");
        let names = check_all(&with, None);
        assert!(names.contains(&"across_seeds.svg"), "{names:?}");
    }
}

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

mod checks;
mod designs;

pub(crate) use checks::{
    assert_inside, assert_no_overprint, assert_paper_width, assert_png_of, assert_well_formed,
};
pub(crate) use designs::{small, wide};

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

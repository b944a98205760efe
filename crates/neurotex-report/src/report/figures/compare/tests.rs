//! The comparison's figures on hand-built comparisons of 2, 10 and 40 candidates, with and
//! without nested selection and conditions.

use super::*;
use crate::compare::{ConditionAccuracy, Nested, Protocol};
use crate::report::figures::tests::{
    assert_inside, assert_no_overprint, assert_paper_width, assert_well_formed,
};

const ENCODINGS: [&str; 3] = ["sa", "fa", "sa+fa"];
const METHODS: [&str; 5] = [
    "glcm3d",
    "glcm2d",
    "spike_stats",
    "volume",
    "haralick_all_offsets_and_directions",
];
const CLASSIFIERS: [&str; 3] = ["knn", "logistic_regression", "nearest_centroid"];

/// `n` candidates, the paper's method among them (third unless `n` < 3), ranked; with
/// `conditions` speeds per candidate (none: pooled) and nested selection when `nested`.
fn comparison(n: usize, nested: bool, conditions: usize) -> Comparison {
    let speeds: Vec<String> = (0..conditions)
        .map(|i| format!("{}", 10 * (i as i32 + 1) * if i % 2 == 0 { 1 } else { -1 }))
        .collect();
    let paper_at = 2.min(n - 1);
    let results: Vec<Ranked> = (0..n)
        .map(|k| {
            let accuracy = 0.92 - 0.6 * k as f64 / n as f64;
            let paper = k == paper_at;
            let (encoding, method, classifier) = if paper {
                ("sa", "glcm3d", "knn")
            } else {
                // from k + 1, so that no other candidate is named as the paper's
                let i = k + 1;
                (
                    ENCODINGS[i % 3],
                    METHODS[(i / 3) % 5],
                    CLASSIFIERS[(i / 15) % 3],
                )
            };
            let versus = (!paper).then(|| (accuracy - 0.8, [0.0004, 0.03, 0.4][k % 3]));
            Ranked {
                encoding: encoding.into(),
                method: method.into(),
                classifier: classifier.into(),
                accuracy,
                ci: [(accuracy - 0.06).max(0.0), (accuracy + 0.05).min(1.0)],
                p_vs_paper: versus.map(|v| v.1),
                difference_vs_paper: versus.map(|v| v.0),
                difference_vs_rates: None,
                p_vs_rates: None,
                per_condition: speeds
                    .iter()
                    .enumerate()
                    .map(|(i, s)| ConditionAccuracy {
                        condition: s.clone(),
                        accuracy: (accuracy + 0.1 * ((i + k) % 3) as f64 - 0.1).clamp(0.0, 1.0),
                    })
                    .collect(),
                seconds: 1.0,
                paper,
                over_encodings: None,
            }
        })
        .collect();
    let protocol = if conditions > 0 {
        Protocol::Per("speed".into())
    } else {
        Protocol::Pooled
    };
    Comparison {
        protocol: protocol.to_string(),
        design: String::new(),
        units: "recordings".into(),
        n_units: 280,
        n_recordings: 280,
        classes: 7,
        chance: 1.0 / 7.0,
        majority: 0.2,
        best: results[0].clone(),
        results,
        nested: nested.then(|| Nested {
            accuracy: 0.81,
            ci: [0.76, 0.86],
            chosen: vec![
                ("sa / glcm3d / knn".into(), 4),
                ("fa / glcm2d / knn".into(), 1),
            ],
            outer_splits: 5,
            inner: "5-fold cross-validation inside each outer training set".into(),
        }),
        caveat: crate::compare::CAVEAT.into(),
        notes: Vec::new(),
        provenance: Vec::new(),
    }
}

/// The SVG's text with the entities plotters writes turned back into characters.
fn plain(svg: &str) -> String {
    svg.replace("&apos;", "'")
        .replace("&lt;", "<")
        .replace("&gt;", ">")
}

fn check(name: &str, svg: &str) {
    assert_paper_width(name, svg);
    assert!(svg.contains("test data"), "{name}: the data's name");
    assert_well_formed(name, svg);
    assert_no_overprint(name, svg);
    assert_inside(name, svg);
    if let Some(dump) = std::env::var_os("NEUROTEX_DUMP_FIGURES") {
        let path = std::path::Path::new(&dump).join(format!("{name}.svg"));
        std::fs::write(path, svg).unwrap();
    }
}

#[test]
fn ranking_names_every_candidate_on_the_canvas() {
    for n in [2, 10, 40] {
        for nested in [false, true] {
            let c = comparison(n, nested, 0);
            let svg = ranking(&c, "test data").unwrap();
            check(&format!("compare_ranking_{n}_{nested}"), &svg);
            let svg = plain(&svg);
            // a name longer than the page leaves room for (the made-up
            // haralick_all_offsets_and_directions here) is cut with an ellipsis
            let rows = rows(&c);
            let room = layout(&rows).name_w;
            for row in &rows {
                let shown = crate::report::figures::plot::fit(&row.label, TICK, room);
                assert!(svg.contains(&shown), "{n}: {shown} missing");
                assert!(n > 10 || !shown.ends_with('…'), "{n}: {shown} cut");
            }
            assert!(svg.contains("sa / glcm3d / knn (paper)"));
            assert!(svg.contains("chance, 1 / 7 classes (14.3 %)"));
            assert!(svg.contains("majority class (20 %)"));
            assert_eq!(svg.contains("nested selection"), nested, "{n}");
            // one dot per row, one per point key of the legend
            let rows = n + usize::from(nested);
            let keys = 2 + usize::from(nested);
            assert_eq!(svg.matches("<circle").count(), rows + keys, "{n} {nested}");
        }
    }
}

#[test]
fn ranking_stars_only_significant_differences_from_the_paper() {
    let svg = plain(&ranking(&comparison(10, false, 0), "test data").unwrap());
    // p cycles through 0.0004, 0.03 and 0.4 over the nine candidates that are not the paper's
    assert!(svg.contains("p < 0.001 *") && svg.contains("p = 0.030 *"));
    assert!(svg.contains("p = 0.400") && !svg.contains("p = 0.400 *"));
    assert!(svg.contains("reference"));
}

#[test]
fn ranking_without_the_paper_drops_its_column_and_balanced_classes_share_one_line() {
    let mut c = comparison(10, true, 0);
    c.results.retain(|r| !r.paper);
    for r in &mut c.results {
        (r.p_vs_paper, r.difference_vs_paper) = (None, None);
    }
    c.majority = c.chance;
    let svg = ranking(&c, "test data").unwrap();
    check("compare_ranking_no_paper", &svg);
    let svg = plain(&svg);
    assert!(!svg.contains(VERSUS_HEAD) && !svg.contains("(paper)"));
    assert!(svg.contains("chance, 1 / 7 classes = majority class (14.3 %)"));
    assert_eq!(
        svg.matches("majority class").count(),
        1,
        "one line, one key"
    );
}

#[test]
fn per_condition_only_with_conditions_and_for_1_to_20() {
    assert!(per_condition(&comparison(10, true, 0)).is_none());
    for conditions in [1, 2, 12, 20] {
        for n in [2, 40] {
            let c = comparison(n, false, conditions);
            let svg = per_condition(&c).unwrap().draw("test data").unwrap();
            check(&format!("compare_per_condition_{n}_{conditions}"), &svg);
            let svg = plain(&svg);
            assert!(svg.contains(&format!("best: {}", name(&c.best))));
            assert!(svg.contains("the paper's method: sa / glcm3d / knn"));
            assert!(svg.contains("chance, 1 / 7 classes"));
            assert!(svg.contains("speed, cross-validated within each"));
            assert!(svg.contains("accuracy per speed"));
            // a marker per condition and line, one per legend key with a marker
            assert_eq!(svg.matches("<circle").count(), 2 * conditions + 2);
        }
    }
}

#[test]
fn per_condition_joins_numbers_by_lines_and_categories_by_none() {
    let c = comparison(4, false, 3);
    let numbers = per_condition(&c).unwrap().draw("test data").unwrap();
    let mut c = comparison(4, false, 3);
    for r in c.results.iter_mut().chain([&mut c.best]) {
        for (p, name) in r.per_condition.iter_mut().zip(["left", "right", "palm"]) {
            p.condition = name.into();
        }
    }
    c.protocol = Protocol::HoldOut("sensor".into()).to_string();
    let svg = per_condition(&c).unwrap().draw("test data").unwrap();
    // The same figure without the candidates' lines (the best's and the paper's, drawn in
    // dashes): the sensors have no order for a line to follow. Chance is a line still.
    let lines = |svg: &str| svg.matches("<polyline").count();
    assert!(
        lines(&svg) < lines(&numbers),
        "{} {}",
        lines(&svg),
        lines(&numbers)
    );
    check("compare_per_condition_categories", &svg);
    assert_eq!(svg.matches("<circle").count(), 2 * 3 + 2);
}

#[test]
fn per_condition_names_the_held_out_column_and_a_paper_best() {
    let mut c = comparison(2, false, 3);
    c.protocol = Protocol::HoldOut("session".into()).to_string();
    c.results.swap(0, 1);
    c.best = c.results[0].clone();
    assert!(c.best.paper);
    let svg = per_condition(&c).unwrap().draw("test data").unwrap();
    check("compare_per_condition_paper_best", &svg);
    let svg = plain(&svg);
    assert!(svg.contains("held-out session, trained on the others"));
    assert!(svg.contains("best, the paper's method: sa / glcm3d / knn"));
    assert_eq!(svg.matches("<circle").count(), 3 + 1);
}

#[test]
fn captions_say_what_is_drawn() {
    let c = comparison(10, true, 4);
    let caption = ranking_caption(&c);
    assert!(
        caption.contains("81.0 %") && caption.contains("5 training sets"),
        "{caption}"
    );
    assert!(!ranking_caption(&comparison(10, false, 0)).contains("nested"));
    assert!(per_condition_caption(&c, None).contains("dashed vermillion"));
}

#[test]
fn column_names_read_as_words_with_their_units() {
    assert_eq!(
        plain_protocol("cross-validation within each `speed_mm_s`, mean over them"),
        "cross-validation within each speed (mm/s), mean over them"
    );
    assert_eq!(
        condition_desc("each `speed_mm_s` held out in turn, mean over them"),
        (
            "speed".to_string(),
            "held-out speed (mm/s), trained on the others".to_string()
        )
    );
    assert_eq!(column_words("session").1, "session");
    assert_eq!(column_words("force_n").1, "force (N)");
}

/// The ranking's text says the network's paired test against its inputs' rates with its
/// verdict, and the design the ranking rests on; a ranking without such a test says none.
#[test]
fn the_network_against_its_rates_is_said_with_a_verdict() {
    use crate::report::comparison::{markdown, text_lines};
    let mut c = comparison(10, false, 2);
    c.design = "5-fold stratified cross-validation, 1 repeat, seed 0".into();
    assert!(!markdown(&c).contains("its inputs' spike rates"));
    for (p, verdict) in [
        (
            0.014,
            "+10.4 points (p 0.014): ahead of its inputs' rates beyond the folds' noise",
        ),
        (
            0.2,
            "+10.4 points (p 0.200): not shown to differ from its inputs' rates",
        ),
    ] {
        (c.results[1].difference_vs_rates, c.results[1].p_vs_rates) = (Some(0.104), Some(p));
        let md = markdown(&c);
        assert!(md.contains(verdict), "{md}");
        assert!(
            md.contains("\n5-fold stratified cross-validation, 1 repeat, seed 0.\n"),
            "{md}"
        );
        assert!(text_lines(&c).iter().any(|l| l.ends_with(verdict)));
    }
    (c.results[1].difference_vs_rates, c.results[1].p_vs_rates) = (Some(-0.06), Some(0.002));
    assert!(markdown(&c).contains("-6.0 points (p 0.002): behind its inputs' rates"));
}

/// With nested selection the ranking says what to train (rank 1, with its command) and what
/// to expect of it (the nested estimate, not rank 1's own accuracy), above the ranking in
/// compare.md; a candidate `neurotex train` does not make is named as such; without nested
/// selection nothing is said.
#[test]
fn a_nested_ranking_says_what_to_train_and_what_to_expect() {
    use crate::report::comparison::{markdown, text_lines};
    let mut c = comparison(6, true, 0);
    let top = &c.results[0];
    let command = format!(
        "`neurotex train --dataset DIR --encoding {} --method {} --classifier {}`",
        top.encoding, top.method, top.classifier
    );
    let expect = "expect about the nested estimate, 81.0% [76.0, 86.0], not rank 1's own 92.0% [86.0, 97.0].";
    let md = markdown(&c);
    assert!(md.contains(&command) && md.contains(expect), "{md}");
    let (nested, table) = (
        md.find("**Nested selection: 81.0% [76.0, 86.0]**"),
        md.find("| rank |"),
    );
    assert!(nested.unwrap() < table.unwrap(), "{md}");
    assert!(text_lines(&c)
        .iter()
        .any(|l| l.starts_with("to use the choice: rank 1") && l.ends_with(expect)));
    c.results[0].method = "van-rossum".into();
    assert!(markdown(&c).contains("`neurotex train` does not make"));
    c.results[0].encoding = "none".into();
    assert!(markdown(&c).contains("a baseline without spikes"));
    let plain = comparison(6, false, 0);
    assert!(
        !markdown(&plain).contains("to use the choice")
            && !markdown(&plain).contains("To use the choice")
    );
}

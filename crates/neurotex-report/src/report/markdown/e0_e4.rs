//! The report's sections on what the spikes hold and how well they classify: E0's spike
//! trains and rate volumes, E1's accuracy, E2's confusions, E3's perturbations, E4's
//! temporal features, and the encoder's sensitivity.

use crate::experiments::{EncoderSensitivity, Results};

use super::super::figures::{self, file};
use super::super::paper::Paper;
use super::super::table::Table;
use super::{bracket, encodings_note, figure, heading, paper_cell, pct, pct_in, skipped_section};

pub(super) fn e1(r: &Results, paper: Option<&Paper>) -> String {
    let asks = "Accuracy per speed: single taxel against 3D-GLCM";
    if let Some(skipped) = skipped_section(r, "e1", asks, "E1") {
        return skipped;
    }
    let mut out = heading(asks, "E1") + &format!("\
        Single taxel: the paper used \"a representative taxel\" without saying which; we report the mean over all taxels as the headline, the mean over the responsive taxels (neither silent nor at the encoder's ceiling in most recordings; see Data) and the best taxel beside it (chosen after the fact, so optimistic). Chance is one over the classes recorded at that speed. Stratified cross-validation, mean over repeats (folds and repeats under Parameters); the 95 % intervals come from a percentile bootstrap over recordings (2000 resamples), each recording's predictions over repeats (and taxels) kept together; where every recording was right (or every one wrong) the bootstrap has no spread, and the Wilson score interval over the recordings is given instead.{}\n\n",
        encodings_note(r)
    );
    let mut header = vec![
        "speed (mm/s)",
        "classes (chance %)",
        "single taxel, mean (%) [95 % interval]",
        "responsive taxels, mean (%)",
        "best taxel (%)",
        "3D-GLCM (%) [95 % interval]",
    ];
    if paper.is_some() {
        header.extend(["paper: single (%)", "paper: 3D-GLCM (%)"]);
    }
    let mut t = Table::new(header);
    for (s, e) in r.e1.iter() {
        let mut row = vec![
            s.to_string(),
            format!("{} ({})", e.classes, pct(e.chance)),
            format!("{} {}", pct(e.taxel_mean), bracket(&e.taxel_mean_interval)),
            e.taxel_mean_responsive.map_or("-".into(), pct),
            format!("{} ({})", pct(e.taxel_best), e.taxel_best_cell),
            format!("{} {}", pct(e.glcm3d), bracket(&e.glcm3d_interval)),
        ];
        if let Some(p) = paper {
            let v = p.e1_at(s);
            row.extend([
                paper_cell(v.map(|v| v.taxel)),
                paper_cell(v.map(|v| v.glcm3d)),
            ]);
        }
        t.row(row);
    }
    out += &t.render();
    out += "\n";
    out += &figure(
        file::E1,
        "E1: bar chart of accuracy per speed, single taxel and 3D-GLCM",
        &figures::e1_caption(r, paper),
    );
    out
}

pub(super) fn e2(r: &Results) -> String {
    let asks = "Which classes are confused";
    let Some(e2) = &r.e2 else {
        return skipped_section(r, "e2", asks, "E2").unwrap_or_default();
    };
    let mut out = heading(&format!("{asks}, at {} mm/s", e2.speed), "E2") + "\
        Rows are the true texture, columns the prediction; counts summed over CV repeats (and over taxels for the single taxel). The paper: the single taxel confuses scotch brite (SB) and styrofoam (STF) with the rug (TRug).\n\n";
    for (name, m) in [
        ("single taxel (all taxels)", &e2.taxel),
        ("3D-GLCM", &e2.glcm3d),
    ] {
        out += &format!("{name}, row percentages:\n\n");
        let mut t = Table::new(
            std::iter::once("true \\ predicted").chain(e2.labels.iter().map(String::as_str)),
        );
        for (label, row) in e2.labels.iter().zip(m) {
            let total = row.iter().sum::<usize>().max(1) as f64;
            let cells = row
                .iter()
                .map(|&v| format!("{:.0}", 100.0 * v as f64 / total));
            t.row(std::iter::once(label.clone()).chain(cells));
        }
        out += &t.render();
        out += "\n";
    }
    out + &figure(
        file::E2,
        "E2: confusion matrices of the single taxel and 3D-GLCM as heat maps",
        &figures::e2_caption(e2),
    )
}

pub(super) fn e3(r: &Results) -> String {
    let asks = "Spatial perturbation: taxels moved";
    let Some(e3) = &r.e3 else {
        return skipped_section(r, "e3", asks, "E3").unwrap_or_default();
    };
    let mut out = heading(&format!("{asks}, at {} mm/s", e3.speed), "E3") + &format!("\
        For each recording, n taxels chosen at random swap places among themselves (every chosen taxel moves; each recording gets its own draw); 3D-GLCM accuracy, mean over {} draws, with a 95 % interval that holds both the recordings' and the draws' variability (a bootstrap that picks one draw, then the recordings), and the standard deviation over draws. Unperturbed 3D-GLCM {} %, single taxel {} %{}. The paper: accuracy falls towards or below the single taxel as n grows.\n\n",
        e3.repeats, pct(e3.glcm3d), pct(e3.taxel_mean),
        r.e1.get(e3.speed).map_or(String::new(), |e| format!(", chance {} %", pct(e.chance))));
    let mut t = Table::new([
        "taxels moved",
        "3D-GLCM (%) [95 % interval]",
        "std over draws (points)",
    ]);
    for (i, ((n, m), s)) in e3.n.iter().zip(&e3.mean).zip(&e3.std).enumerate() {
        t.row([n.to_string(), pct_in(*m, e3.interval.get(i)), pct(*s)]);
    }
    out += &t.render();
    out += "\n";
    out + &figure(
        file::E3,
        "E3: line chart of 3D-GLCM accuracy against the number of taxels moved",
        &figures::e3_caption(e3),
    )
}

pub(super) fn e4(r: &Results, paper: Option<&Paper>) -> String {
    let asks = "Temporal information: 2D-GLCM without the time axis";
    if let Some(skipped) = skipped_section(r, "e4", asks, "E4") {
        return skipped;
    }
    let mut out = heading(asks, "E4");
    let mut header = vec![
        "speed (mm/s)",
        "chance (%)",
        "single taxel (%) [95 % interval]",
        "2D-GLCM (%) [95 % interval]",
        "3D-GLCM (%) [95 % interval]",
    ];
    if paper.is_some() {
        header.extend(["paper: single", "paper: 2D", "paper: 3D"]);
    }
    let mut t = Table::new(header);
    for (s, e) in r.e4.iter() {
        // The single taxel and 3D-GLCM are E1's, with E1's intervals.
        let e1 = r.e1.get(s);
        let with = pct_in;
        let mut row = vec![
            s.to_string(),
            e1.map_or("-".into(), |e| pct(e.chance)),
            with(e.taxel_mean, e1.map(|e| &e.taxel_mean_interval)),
            with(e.glcm2d, Some(&e.glcm2d_interval)),
            with(e.glcm3d, e1.map(|e| &e.glcm3d_interval)),
        ];
        if let Some(p) = paper {
            let e1 = p.e1_at(s);
            row.extend([
                paper_cell(e1.map(|v| v.taxel)),
                paper_cell(p.e4_2d_at(s)),
                paper_cell(e1.map(|v| v.glcm3d)),
            ]);
        }
        t.row(row);
    }
    out += &t.render();
    out += "\n";
    out + &figure(
        file::E4,
        "E4: bar chart of single taxel, 2D-GLCM and 3D-GLCM accuracy per speed",
        &figures::e4_caption(r, paper),
    )
}

pub(super) fn e0(r: &Results) -> String {
    let Some(e0) = &r.e0 else {
        return String::new();
    };
    heading("Spike trains and rate volumes of two classes", "E0")
        + &figure(
            file::E0,
            "E0: PSTH of one taxel beside the rate volume of the array, for two textures",
            &figures::e0_caption(e0),
        )
}

pub(super) fn encoder_sensitivity(r: &Results) -> String {
    let Some(s) = &r.encoder_sensitivity else {
        return String::new();
    };
    let out = format!(
        "## The encoder's sensitivity\n\n\
         Spiking neurons turn a signal into threshold crossings: a neuron near its threshold can fire a step earlier or later, or once more or less, when its input moves by far less than any sensor resolves, and those spikes move features and sometimes predictions. So E1, E4, E6 and E8 classify every recording under {n} encodings: as run, and {more} more with each input sample multiplied by 1 + u x {eps:e} (u uniform in [-1, 1), independent). Their accuracies are means over the encodings, their intervals resample encodings as well as recordings, and their claims are judged on those. {spread}\n\n",
        n = s.encodings,
        more = s.encodings - 1,
        eps = s.perturbation,
        spread = match s.largest_spread > 0.0 {
            true => format!("One encoding's accuracy differs from another's by up to {} points here; the other analyses use the encoding as run, so a difference between them smaller than that is within the encoder's noise.", pct(s.largest_spread)),
            false => "Every encoding gave the same accuracies here: the encoder added no noise to them.".to_string(),
        }
    );
    let mut t = Table::new(vec![
        "speed (mm/s)",
        "method",
        "as run (%) [95 % interval, recordings only]",
        "range over encodings (%)",
        "mean over encodings (%) [95 % interval, recordings and encodings]",
    ]);
    for (speed, e) in s.speeds.iter() {
        let methods = [
            ("3D-GLCM", &e.glcm3d),
            ("single taxel, mean", &e.taxel_mean),
            ("2D-GLCM", &e.glcm2d),
        ];
        for (name, a) in methods {
            let (lo, hi) = a.range();
            let i = &a.recordings_only;
            t.row(vec![
                speed.to_string(),
                name.to_string(),
                format!("{} {}", pct(i.estimate), bracket(i)),
                format!("{}-{}", pct(lo), pct(hi)),
                format!("{} {}", pct(a.mean()), bracket(&a.combined)),
            ]);
        }
    }
    out + &t.render() + "\n" + &spike_agreement(s)
}

/// How far the perturbed encodings' spikes are those as run, per speed.
fn spike_agreement(s: &EncoderSensitivity) -> String {
    let mut t = Table::new(vec![
        "speed (mm/s)",
        "recordings whose spikes changed",
        "spikes as run at the same 1 ms step in a perturbed encoding (%)",
        "within 10 ms (%)",
        "spikes, perturbed / as run",
        "a taxel's train first departs at (s into the recording, median over the trains that depart)",
    ]);
    let mut any = false;
    for (speed, e) in s.speeds.iter() {
        let Some(a) = &e.timing else { continue };
        any = true;
        let share = |k: usize| pct(k as f64 / a.spikes.max(1) as f64);
        t.row(vec![
            speed.to_string(),
            format!("{} of {}", e.recordings_changed, e.recordings),
            share(a.same_step),
            share(a.near),
            format!("{:.3}", a.perturbed_spikes as f64 / a.spikes.max(1) as f64),
            a.median_first_departure_s
                .map_or("never".into(), |d| format!("{d:.2}")),
        ]);
    }
    if !any {
        return String::new();
    }
    "What the perturbations do to the spikes: each taxel's train in each perturbed encoding against the same taxel's train as run, pooled over the speed's recordings. A train keeps the spikes as run to the step until its first departure. With the overshoot kept (Izhikevich's reference code, the default: two Euler half steps of 0.5 ms carry the membrane far past the 30 mV peak at a spike, and the recovery reads that value) how far it overshoots moves with the input's last bits and sets the next interval, so after a departure the trains drift apart in timing while their counts stay close; with `--overshoot capped` the recovery reads the membrane capped at the peak and the trains stay together (the Parameters say which the run used; docs/decisions/0031-overshoot-kept-by-default-capped-on-request.md).\n\n".to_string()
        + &t.render()
        + "\n"
}

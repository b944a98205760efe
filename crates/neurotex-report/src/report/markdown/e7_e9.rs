//! The report's sections on E7's gain, E8's neighbouring taxels and E9's comparison with
//! baselines and a spiking network.

use crate::experiments::Results;

use super::super::figures::{self, file};
use super::super::table::Table;
use super::{figure, heading, pct, pct_in, skipped_section};
use neurotex_core::words::signed_one_decimal as signed;

pub(super) fn e7(r: &Results) -> String {
    let Some(e7) = &r.e7 else {
        return String::new();
    };
    let asks = format!(
        "The encoder's gain: firing rates and intervals, at {} mm/s",
        e7.speed
    );
    let mut out = heading(&asks, "E7") + &format!("\
        Mean firing rate per taxel (Hz) for each gain and texture; the paper chose G = {} as the balance between sparse responses (low G) and saturated, less discriminative ones (high G).\n\n",
        super::super::paper::PAPER_GAIN);
    let mut t = Table::new(std::iter::once("G").chain(e7.sweep.labels.iter().map(String::as_str)));
    for (g, rates) in e7.sweep.gains.iter().zip(&e7.rate_hz) {
        t.row(std::iter::once(g.to_string()).chain(rates.iter().map(|r| format!("{r:.1}"))));
    }
    out += &t.render();
    out += "\n";
    out += &figure(
        file::E7_RATE,
        "E7: line chart of firing rate against gain, one line per texture",
        &figures::e7_rate_caption(e7),
    );
    out + &figure(
        file::E7_ISI,
        "E7: one panel per gain of the cumulative ISI distribution of each texture",
        &figures::e7_isi_caption(e7),
    )
}

pub(super) fn e8(r: &Results) -> String {
    let asks = "Robustness to the number of neighbours k";
    if let Some(skipped) = skipped_section(r, "e8", asks, "E8") {
        return skipped;
    }
    let over = match r.e8.values().next().map_or(1, |e| e.encodings) {
        1 => "recordings".to_string(),
        n => format!("recordings and {n} encodings, as E1"),
    };
    let mut out = heading(asks, "E8") + &format!("Single taxel (mean over taxels) and 3D-GLCM accuracy (%) for each number of neighbours k, with 95 % intervals (bootstrap over {over}). The paper: the outperformance is robust to k.\n\n");
    let mut t = Table::new([
        "speed (mm/s)",
        "chance (%)",
        "k",
        "single taxel (%) [95 % interval]",
        "3D-GLCM (%) [95 % interval]",
    ]);
    for (s, e) in r.e8.iter() {
        let chance = r.e1.get(s).map_or("-".into(), |e| pct(e.chance));
        for (i, k) in e.k.iter().enumerate() {
            t.row([
                s.to_string(),
                chance.clone(),
                k.to_string(),
                pct_in(e.taxel_mean[i], e.taxel_mean_interval.get(i)),
                pct_in(e.glcm3d[i], e.glcm3d_interval.get(i)),
            ]);
        }
    }
    out += &t.render();
    out += "\n";
    out + &figure(
        file::E8,
        "E8: one line chart per speed of accuracy against k",
        &figures::e8_caption(r),
    )
}

pub(super) fn e9(r: &Results) -> String {
    let asks = "The best of `neurotex compare`'s candidates";
    let Some(e9) = &r.e9 else {
        return skipped_section(r, "e9", asks, "E9, beyond the paper").unwrap_or_default();
    };
    let (within, held) = (&e9.per_speed, &e9.held_out);
    let mut out = format!(
        "## {asks} (E9, beyond the paper)\n\n\
         {} candidates (encodings, feature methods, classifiers: see `neurotex compare --help`) on the same folds: \
         accuracy (%) of the paper's method (SA, 3D-GLCM, KNN) and of the best candidate, cross-validated within each speed \
         and with each speed held out (trained on the others, E6's question). Intervals: 95 % bootstrap over {}. \
         E9 runs every candidate with its own number of cross-validation repeats (under Parameters; fewer than E1's by default) and on the encoding as run, \
         so its paper's-method accuracy may differ from E1's (a mean over more repeats and encodings) by a few points. \
         **Caveat**: {}.\n\n",
        within.results.len(),
        within.units,
        within.caveat
    );
    out += &e9_table(within, held);
    for (protocol, c) in [
        ("within each speed", within),
        ("with each speed held out", held),
    ] {
        if let Some(n) = &c.nested {
            let chosen: Vec<String> = n
                .chosen
                .iter()
                .map(|(c, k)| format!("{c} ({k} of {})", n.outer_splits))
                .collect();
            out += &format!(
                "\nNested selection {protocol} (the candidate chosen inside each training set; the number to quote): {} [{}, {}] % (chose {}).\n",
                pct(n.accuracy), pct(n.ci[0]), pct(n.ci[1]), chosen.join(", ")
            );
        }
    }
    out += &e9_baselines(e9.baselines.as_ref());
    out += &e9_spiking(e9.spiking.as_ref());
    out += "\n";
    out + &figure(
        file::E9_PER_SPEED,
        "E9: every candidate's accuracy within each speed, ranked, with nested selection",
        &figures::compare::ranking_caption(within),
    ) + &figure(
        file::E9_HELD_OUT,
        "E9: every candidate's accuracy with each speed held out, ranked, with nested selection",
        &figures::compare::ranking_caption(held),
    ) + &if figures::compare::per_condition(held).is_some() {
        figure(
            file::E9_SPEEDS,
            "E9: the best candidate, the paper's method and the best baseline without spikes at each held-out speed",
            &figures::compare::per_condition_caption(held, e9.held_out_baseline()),
        )
    } else {
        String::new()
    }
}

/// E9's baselines without spikes beside the spike candidates: the best of each protocol.
fn e9_baselines(baselines: Option<&crate::experiments::Baselines>) -> String {
    use crate::experiments::Baselines;
    let best = |c: &crate::compare::Comparison| {
        let b = &c.best;
        format!(
            "{} % [{}, {}] ({} / {} / {})",
            pct(b.accuracy),
            pct(b.ci[0]),
            pct(b.ci[1]),
            b.encoding,
            b.method,
            b.classifier
        )
    };
    match baselines {
        None => String::new(),
        Some(Baselines::Skipped(why)) => {
            format!("\nThe baselines without spikes were not run: {why}.\n")
        }
        Some(Baselines::Compared {
            per_speed,
            held_out,
        }) => format!(
            "\nBaselines without spikes on the same folds (`neurotex compare --encodings none`: the spectrum and the statistics of the conditioned signal the encoder receives, with each classifier; not among the candidates above): the best within each speed {}, with each speed held out {}. They say what the spikes cost or gain against the signal they are made from.\n",
            best(per_speed),
            best(held_out)
        ),
    }
}

/// The spiking network beside the paper's method and its inputs' spike rates on E9's folds
/// (`reproduce --snn`).
fn e9_spiking(spiking: Option<&crate::experiments::Spiking>) -> String {
    use crate::experiments::Spiking;
    let Some(s) = spiking else {
        return String::new();
    };
    let (within, held) = (&s.per_speed, &s.held_out);
    let (Some((net_w, paper_w)), Some((net_h, paper_h))) =
        (Spiking::pair(within), Spiking::pair(held))
    else {
        return String::new();
    };
    let mut out = format!(
        "\n### The spiking network beside the paper's method and its inputs' spike rates\n\n\
         A spiking network (`--classifier snn`: one hidden layer of current-based leaky integrate-and-fire neurons and a leaky readout, \
         trained with surrogate gradients; see docs/spiking-classifier.md) reads the SA+FA spike trains themselves instead of features. \
         Its hyperparameters are its defaults, so no selection on these recordings flatters it (all were fixed before any data but one: standardised inputs, chosen over the counts as they are on this simulator's seed-0 dataset and on FabricSlide); it ran on the same folds and the same encoding (as run) as the paper's method (SA, 3D-GLCM, KNN). \
         Accuracy (%), intervals 95 % bootstrap over {}; chance {} % within each speed and {} % with each speed held out.\n\n",
        within.units,
        pct(within.chance),
        pct(held.chance)
    );
    let rates = (Spiking::rates(within), Spiking::rates(held));
    let mut t = Table::new(vec![
        "speed (mm/s)",
        "paper, within speed",
        "rates, within speed",
        "network, within speed",
        "paper, speed held out",
        "rates, speed held out",
        "network, speed held out",
    ]);
    let columns = [
        Some(paper_w),
        rates.0,
        Some(net_w),
        Some(paper_h),
        rates.1,
        Some(net_h),
    ];
    for (i, c) in net_w.per_condition.iter().enumerate() {
        let at = |x: &Option<&crate::compare::Ranked>| {
            x.and_then(|x| x.per_condition.get(i))
                .map_or("-".into(), |p| pct(p.accuracy))
        };
        t.row(std::iter::once(c.condition.clone()).chain(columns.iter().map(at)));
    }
    let mean = |x: &Option<&crate::compare::Ranked>| match x {
        Some(x) => format!("{} [{}, {}]", pct(x.accuracy), pct(x.ci[0]), pct(x.ci[1])),
        None => "-".into(),
    };
    t.row(std::iter::once("mean [95 % CI]".to_string()).chain(columns.iter().map(mean)));
    out += &t.render();
    out += &format!(
        "\nThe network against the paper's method (paired sign-flip test over {}): within each speed {}, with each speed held out {}. \
         Their training and testing times are under Timing.\n",
        within.units,
        super::super::comparison::versus_paper(net_w),
        super::super::comparison::versus_paper(net_h),
    );
    out + &timing_adds(net_w, net_h, rates)
}

/// What the network draws beyond its inputs' spike counts: its accuracy minus that of their
/// rates with logistic regression (`rates`), on the same folds.
fn timing_adds(
    net_w: &crate::compare::Ranked,
    net_h: &crate::compare::Ranked,
    rates: (
        Option<&crate::compare::Ranked>,
        Option<&crate::compare::Ranked>,
    ),
) -> String {
    let (Some(rates_w), Some(rates_h)) = rates else {
        return String::new();
    };
    // The paired test where the comparison ran it (both candidates of one encoding), else
    // the difference alone.
    let points = |net: &crate::compare::Ranked, rates: &crate::compare::Ranked| match net.p_vs_rates
    {
        Some(p) => super::super::comparison::versus_text(net.accuracy - rates.accuracy, p),
        None => format!("{} points", signed(100.0 * (net.accuracy - rates.accuracy))),
    };
    format!(
        "\nThe rates columns are the network's own inputs (SA+FA spike trains) reduced to each taxel's mean spike rate (spikes/s) and classified by logistic regression (`sa+fa / rates / linear`). \
         The network is {} from them within each speed and {} with each speed held out \
         (the network minus the rates, from the unrounded accuracies, on the same folds{}; their intervals are in the table). \
         That difference is what the network draws beyond its inputs' spike counts: the timing of the spikes together with its own nonlinearity and training, \
         so a gain near zero says the network reads rates, and a gain is not the timing's alone (a nonlinear classifier on the rates, `compare --methods rates`, separates the two).\n",
        points(net_w, rates_w),
        points(net_h, rates_h),
        match net_w.p_vs_rates.is_some() && net_h.p_vs_rates.is_some() {
            true => ", with the p-value of the paired sign-flip test over the same units as above",
            false => "; these results were written before the paired test between the two was run",
        },
    )
}

/// E9's table: per speed, the paper's method and the best candidate within the speed and
/// with it held out; the means with their intervals last.
fn e9_table(within: &crate::compare::Comparison, held: &crate::compare::Comparison) -> String {
    use crate::compare::Ranked;
    let name = |x: &Ranked| format!("{} / {} / {}", x.encoding, x.method, x.classifier);
    let paper = |c: &crate::compare::Comparison| c.results.iter().find(|x| x.paper).cloned();
    let mut t = Table::new([
        "speed (mm/s)".to_string(),
        "paper, within speed".into(),
        format!("best within speed: {}", name(&within.best)),
        "paper, speed held out".into(),
        format!("best held out: {}", name(&held.best)),
    ]);
    let columns = [
        paper(within),
        Some(within.best.clone()),
        paper(held),
        Some(held.best.clone()),
    ];
    for (i, c) in within.best.per_condition.iter().enumerate() {
        let at = |x: &Option<Ranked>| {
            x.as_ref()
                .and_then(|x| x.per_condition.get(i))
                .map_or("-".into(), |p| pct(p.accuracy))
        };
        t.row(std::iter::once(c.condition.clone()).chain(columns.iter().map(at)));
    }
    let mean = |x: &Option<Ranked>| {
        x.as_ref().map_or("-".into(), |x| {
            format!("{} [{}, {}]", pct(x.accuracy), pct(x.ci[0]), pct(x.ci[1]))
        })
    };
    t.row(std::iter::once("mean [95 % CI]".to_string()).chain(columns.iter().map(mean)));
    t.render()
}

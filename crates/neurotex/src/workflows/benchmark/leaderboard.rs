//! The leaderboard: per dataset and protocol, the nested estimate, the ranked candidates
//! with their intervals, chance, the paired test against the paper's method, and the
//! published results beside ours.

use serde::{Deserialize, Serialize};

use super::candidate_set;
use crate::classify::metrics::{chance_level, AgainstChance};
use crate::compare::{Comparison, Ranked};
use crate::datasets::recipe::ProtocolSpec;
use crate::datasets::{Published, Recipe};
use crate::report::figures::leaderboard::{Entry, Group, Kind};
use neurotex_core::words::signed_one_decimal as signed;

/// Candidates listed in full per board; the paper's method, the spike counts with logistic
/// regression and the best baseline without spikes are listed below them when lower.
const TOP: usize = 10;

/// Every dataset x protocol of one run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Leaderboard {
    /// The version of the candidate set.
    pub candidate_set: u32,
    /// The seed of folds, bootstrap and tests.
    pub seed: u64,
    /// Cross-validation folds.
    pub folds: usize,
    /// Cross-validation repeats.
    pub repeats: usize,
    /// Whether the spiking network was among the candidates.
    pub snn: bool,
    /// The version of neurotex that made it.
    pub neurotex: String,
    /// One board per dataset and protocol, in the order run.
    pub boards: Vec<Board>,
}

/// One dataset under one protocol.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Board {
    /// The recipe's name.
    pub dataset: String,
    /// The recipe's title.
    pub title: String,
    /// The data's citation.
    pub citation: String,
    /// The data's licence.
    pub licence: String,
    /// The protocol's id.
    pub protocol_id: String,
    /// The protocol in words.
    pub protocol: String,
    /// The comparison, as `compare --nested` gives it.
    pub comparison: Comparison,
    /// Results published on the data, shown beside this protocol.
    pub published: Vec<Published>,
}

impl Board {
    /// The board of `recipe` under `protocol`.
    pub fn of(
        recipe: &Recipe,
        protocol: &ProtocolSpec,
        comparison: Comparison,
        published: Vec<Published>,
    ) -> Board {
        Board {
            dataset: recipe.name.clone(),
            title: recipe.title.clone(),
            citation: recipe.citation.clone(),
            licence: recipe.licence.clone(),
            protocol_id: protocol.id.clone(),
            protocol: protocol.describe(),
            comparison,
            published,
        }
    }
}

impl Leaderboard {
    /// One line per board: the nested estimate, the best candidate and chance.
    pub fn summary(&self) -> Vec<String> {
        let line = |b: &Board| {
            let c = &b.comparison;
            let (level, _) = chance_level(c.classes, c.majority);
            let nested = c.nested.as_ref().map_or(String::new(), |n| {
                let flag = chance_flag(n.ci, level).map_or(String::new(), |f| format!(" ({f})"));
                format!(
                    "nested {} % [{}, {}]{flag}; ",
                    pct(n.accuracy),
                    pct(n.ci[0]),
                    pct(n.ci[1])
                )
            });
            format!(
                "{} / {}: {nested}best {} {} %; chance {} %, majority class {} %",
                b.dataset,
                b.protocol_id,
                name(&c.best),
                pct(c.best.accuracy),
                pct(c.chance),
                pct(c.majority)
            )
        };
        self.boards.iter().map(line).collect()
    }
}

impl Board {
    /// The board's rows in the leaderboard's figure.
    pub fn figure_group(&self) -> Group {
        let c = &self.comparison;
        let mut rows = Vec::new();
        if let Some(n) = &c.nested {
            rows.push(Entry {
                label: "nested selection".into(),
                accuracy: n.accuracy,
                ci: Some(n.ci),
                kind: Kind::Nested,
            });
        }
        let ranked = |kind: Kind, r: Option<&Ranked>| {
            r.map(|r| Entry {
                label: format!("{} / {} / {}", r.encoding, r.method, r.classifier),
                accuracy: r.accuracy,
                ci: Some(r.ci),
                kind,
            })
        };
        let spikes = c.results.iter().find(|r| r.encoding != "none");
        let rates = (c.results.iter())
            .filter(|r| is_rates(r))
            .max_by(|a, b| a.accuracy.total_cmp(&b.accuracy));
        let none = c.results.iter().find(|r| r.encoding == "none");
        let paper = c.results.iter().find(|r| r.paper);
        rows.extend(ranked(Kind::Spikes, spikes));
        rows.extend(ranked(Kind::Rates, rates));
        rows.extend(ranked(Kind::NoSpikes, none));
        rows.extend(ranked(Kind::Paper, paper));
        rows.extend(self.published.iter().map(|p| Entry {
            label: p.citation.clone(),
            accuracy: p.accuracy,
            ci: None,
            kind: match p.same_protocol {
                true => Kind::Published,
                false => Kind::PublishedOther,
            },
        }));
        Group {
            title: format!("{}: {}", self.dataset, self.protocol),
            // One over the classes, as the tables' chance column.
            chance: c.chance,
            rows,
        }
    }
}

/// The flag of a nested interval at or under chance (`compare`'s note, among the board's
/// notes, says what it means).
fn chance_flag(ci: [f64; 2], chance: f64) -> Option<&'static str> {
    AgainstChance::of(ci, chance).map(|at| match at {
        AgainstChance::Below => "below chance",
        AgainstChance::Includes => "not above chance",
    })
}

/// A share as a percentage with one decimal.
fn pct(x: f64) -> String {
    format!("{:.1}", 100.0 * x)
}

/// A candidate's name as `compare` writes it, with what it stands for.
fn name(r: &Ranked) -> String {
    let role = if r.paper {
        " (the paper's method)"
    } else if is_rates(r) {
        " (spike counts, logistic regression)"
    } else if r.encoding == "none" {
        " (no spikes)"
    } else {
        ""
    };
    format!("{} / {} / {}{role}", r.encoding, r.method, r.classifier)
}

/// One table row of a ranked candidate.
fn row(rank: usize, r: &Ranked) -> String {
    let vs = match (r.difference_vs_paper, r.p_vs_paper) {
        (Some(d), Some(p)) if p < 0.001 => format!("{} | < 0.001", signed(100.0 * d)),
        (Some(d), Some(p)) => format!("{} | {p:.3}", signed(100.0 * d)),
        _ => "— | —".to_string(),
    };
    format!(
        "| {rank} | {} | {} | {}–{} | {vs} |",
        name(r),
        pct(r.accuracy),
        pct(r.ci[0]),
        pct(r.ci[1])
    )
}

/// The leaderboard as Markdown.
pub fn markdown(board: &Leaderboard) -> String {
    let (encodings, methods, classifiers) = candidate_set(board.snn);
    let mut s = format!(
        "# Leaderboard\n\n![the leaderboard](leaderboard.png)\n\nCandidate set {}: encodings {encodings} (`none`: the baselines without spikes, from the signal the encoder would receive), methods {methods}, classifiers {classifiers}, every pairing `neurotex compare` runs. Each protocol is `neurotex compare --nested` on the recipe's dataset: accuracies are means over the protocol's conditions, with 95 % bootstrap intervals over recordings; Δ and p are against the paper's method (SA, 3D-GLCM, KNN), by the paired sign-flip test. The top candidate of a ranking is chosen on the recordings it is scored on and is biased upwards; the nested estimate (the best chosen inside each training set) is the one to quote. {} folds, {} repeat(s), seed {}; neurotex {}.\n",
        board.candidate_set, board.folds, board.repeats, board.seed, board.neurotex
    );
    for b in &board.boards {
        s.push_str(&section(b));
    }
    s
}

/// The ranking's table: the first [`TOP`] candidates, then the paper's method, the spike
/// counts with logistic regression and the best baseline without spikes where lower, the
/// ranks left out said; and a note when the first candidates tie.
fn table(c: &Comparison) -> String {
    let mut s = String::new();
    s.push_str("| rank | candidate | accuracy, % | 95 % interval | Δ vs paper, points | p |\n|---|---|---|---|---|---|\n");
    let mut shown = 0;
    for (i, r) in c.results.iter().enumerate() {
        let marked = r.paper
            || is_rates(r)
            || c.results.iter().position(|x| x.encoding == "none") == Some(i);
        if i < TOP || marked {
            if i > shown {
                s.push_str(&format!(
                    "| … | ranks {}–{} in compare.md | | | | |\n",
                    shown + 1,
                    i
                ));
            }
            s.push_str(&row(i + 1, r));
            s.push('\n');
            shown = i + 1;
        }
    }
    if shown < c.results.len() {
        s.push_str(&format!(
            "| … | ranks {}–{} in compare.md | | | | |\n",
            shown + 1,
            c.results.len()
        ));
    }
    let tied = c
        .results
        .iter()
        .take_while(|r| r.accuracy == c.best.accuracy)
        .count();
    if tied > 1 {
        s.push_str(&format!(
            "\nThe first {tied} candidates tie at {} %: the order among them is the order they were listed in, not a ranking.\n",
            pct(c.best.accuracy)
        ));
    }
    s
}

/// Whether `r` is the spike counts with logistic regression.
fn is_rates(r: &Ranked) -> bool {
    r.method == "rates" && r.classifier == "linear"
}

/// One board's section.
fn section(b: &Board) -> String {
    let c = &b.comparison;
    let mut s = format!(
        "\n## {}: {}\n\n{} ({}; licence {}).\n\n{} recordings, {} classes; chance {} %, majority class {} %.\n\n",
        b.dataset,
        b.protocol,
        b.title,
        b.citation,
        b.licence,
        c.n_recordings,
        c.classes,
        pct(c.chance),
        pct(c.majority)
    );
    if let Some(n) = &c.nested {
        // Every candidate chosen as often as the most chosen one, not the first of a tie.
        let most = n.chosen.first().map_or(0, |c| c.1);
        let names: Vec<&str> = (n.chosen.iter())
            .take_while(|c| c.1 == most)
            .map(|c| c.0.as_str())
            .collect();
        let chosen = match names.len() {
            0 => String::new(),
            1 => format!(
                "; chosen most often: {} ({most} of {} splits)",
                names[0], n.outer_splits
            ),
            _ => format!(
                "; chosen most often, {most} of {} splits each: {}",
                n.outer_splits,
                names.join(", ")
            ),
        };
        let inner = match n.inner.is_empty() {
            true => String::new(),
            false => format!(" Ranked by {}.", n.inner),
        };
        s.push_str(&format!(
            "**Nested selection: {} % (95 % interval {}–{} %)**{chosen}.{inner}\n\n",
            pct(n.accuracy),
            pct(n.ci[0]),
            pct(n.ci[1])
        ));
        let (level, words) = chance_level(c.classes, c.majority);
        if let Some(flag) = chance_flag(n.ci, level) {
            s.push_str(&format!(
                "**{}{}** ({words}).\n\n",
                flag[..1].to_uppercase(),
                &flag[1..],
            ));
        }
    }
    for note in &c.notes {
        s.push_str(&format!("Note: {note}.\n\n"));
    }
    s.push_str(&table(c));
    if !b.published.is_empty() {
        s.push_str("\nPublished on these data:\n\n| accuracy, % | who | their method and protocol | the same protocol as above |\n|---|---|---|---|\n");
        for p in &b.published {
            let same = match p.same_protocol {
                true => "yes",
                false => "no: other splits or conditions, not comparable point for point",
            };
            s.push_str(&format!(
                "| {} | {} | {} | {same} |\n",
                pct(p.accuracy),
                p.citation,
                p.protocol
            ));
        }
    }
    let dir = format!("{}/{}", b.dataset, b.protocol_id);
    s.push_str(&format!(
        "\nEvery candidate, the figures and the notes: [{dir}/compare.md]({dir}/compare.md), ![ranking]({dir}/ranking.png)\n"
    ));
    s
}

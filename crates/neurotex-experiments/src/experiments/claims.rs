//! The paper's conclusions judged on our results: each claim is a function of [`Results`]
//! that says whether the claim holds here and on which numbers. The report only prints them.

use serde::{Deserialize, Serialize};

use super::{Comparison, Results};
use crate::classify::PairedVerdict;
use neurotex_core::words::signed_one_decimal as signed;

/// Whether a claim of the paper holds on these results: by a paired comparison on the same
/// recordings where the analysis has one, else by point estimates only (and says so).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// Significant in the paper's direction wherever it is tested.
    Holds,
    /// Within noise somewhere, and significant against it nowhere.
    NotShown,
    /// Significant against the paper's direction somewhere.
    Contradicted,
    /// No test: our point estimates agree with the claim.
    PointAgrees,
    /// No test: our point estimates disagree with the claim.
    PointDisagrees,
    /// These results cannot speak to the claim (an accuracy at the ceiling, a single `k`
    /// evaluated); the detail says why.
    NotJudged,
}

impl Verdict {
    fn of(holds: bool) -> Self {
        if holds {
            Verdict::PointAgrees
        } else {
            Verdict::PointDisagrees
        }
    }

    /// The verdict of a claim tested at several conditions, from each condition's paired
    /// comparison.
    fn tested(verdicts: impl IntoIterator<Item = PairedVerdict>) -> Self {
        let all: Vec<PairedVerdict> = verdicts.into_iter().collect();
        if all.contains(&PairedVerdict::Contradicted) {
            Verdict::Contradicted
        } else if !all.is_empty() && all.iter().all(|v| *v == PairedVerdict::Supported) {
            Verdict::Holds
        } else {
            Verdict::NotShown
        }
    }

    /// Whether the claim holds (by test, or in point estimates where there is none).
    pub fn holds(self) -> bool {
        matches!(self, Verdict::Holds | Verdict::PointAgrees)
    }

    /// How the report and the command line say it.
    pub fn describe(self) -> &'static str {
        match self {
            Verdict::Holds => "Holds (paired test)",
            Verdict::NotShown => "Not shown to hold (paired test not significant everywhere)",
            Verdict::Contradicted => "Contradicted (paired test)",
            Verdict::PointAgrees => "Agrees in point estimates (no test)",
            Verdict::PointDisagrees => "Disagrees in point estimates (no test)",
            Verdict::NotJudged => "Not judged here",
        }
    }
}

/// One conclusion of the paper and its verdict on our results.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Claim {
    /// The claim, prefixed by its analysis (`E1: ...`).
    pub statement: String,
    /// Whether it holds here.
    pub verdict: Verdict,
    /// The numbers the verdict rests on (may be empty).
    pub detail: String,
}

impl Claim {
    fn new(statement: &str, holds: bool, detail: String) -> Self {
        Self::judged(statement, Verdict::of(holds), detail)
    }

    fn judged(statement: &str, verdict: Verdict, detail: String) -> Self {
        Claim {
            statement: statement.to_string(),
            verdict,
            detail,
        }
    }
}

/// `a - b` with its interval, in points.
fn difference(c: &Comparison) -> String {
    format!(
        "{} points [{}, {}]",
        signed(100.0 * c.difference),
        signed(100.0 * c.lower),
        signed(100.0 * c.upper)
    )
}

fn pct(a: f64) -> String {
    format!("{:.1}", 100.0 * a)
}

/// Every claim these results can judge, in the paper's order; a claim whose analysis was
/// skipped (or whose textures are absent) is left out.
pub fn claims(r: &Results) -> Vec<Claim> {
    let mut out = e1_claims(r);
    out.extend(e2_claims(r));
    out.extend(e3_claims(r));
    out.extend(e4_claim(r));
    out.extend(e5_claims(r));
    out.extend(e6_claim(r));
    out.extend(e8_claim(r));
    out
}

fn e1_claims(r: &Results) -> Vec<Claim> {
    if r.e1.is_empty() {
        return Vec::new();
    }
    let verdict = Verdict::tested(r.e1.values().map(|e| e.glcm3d_vs_taxel.verdict));
    let detail =
        r.e1.iter()
            .map(|(s, e)| {
                let d = difference(&e.glcm3d_vs_taxel);
                format!(
                    "{s} mm/s: {} vs {} %, {d}",
                    pct(e.glcm3d),
                    pct(e.taxel_mean)
                )
            })
            .collect::<Vec<_>>()
            .join("; ");
    let mut out = vec![Claim::judged(
        "E1: 3D-GLCM beats the single taxel (mean over taxels) at every speed",
        verdict,
        detail,
    )];
    out.push(Claim::new(
        "E1: 3D-GLCM beats even the best taxel chosen after the fact",
        r.e1.values().all(|e| e.glcm3d > e.taxel_best),
        r.e1.iter()
            .map(|(s, e)| format!("{s} mm/s: best taxel {} %", pct(e.taxel_best)))
            .collect::<Vec<_>>()
            .join("; "),
    ));
    if r.e1.len() >= 2 {
        // Slow to fast by magnitude: signed speeds are directions, not slower conditions.
        let mut by_magnitude: Vec<_> = r.e1.iter().collect();
        by_magnitude.sort_by(|a, b| a.0.mm_s().abs().total_cmp(&b.0.mm_s().abs()));
        let margins: Vec<f64> = by_magnitude
            .iter()
            .map(|(_, e)| e.glcm3d - e.taxel_mean)
            .collect();
        let numbers = by_magnitude
            .iter()
            .zip(&margins)
            .map(|((s, _), m)| format!("{s} mm/s: {}", signed(100.0 * m)))
            .collect::<Vec<_>>()
            .join(", ")
            + " points";
        let statement = "E1: 3D-GLCM's lead over the single taxel shrinks from the slowest to the fastest speed";
        let (slowest, first) = (by_magnitude[0].0, margins[0]);
        let claim = if by_magnitude.iter().any(|(_, e)| e.glcm3d >= 1.0) {
            let why = "3D-GLCM is at 100 % at some speed, where its lead is capped by the ceiling";
            Claim::judged(statement, Verdict::NotJudged, format!("{why}: {numbers}"))
        } else if first <= 0.0 {
            let why = format!("3D-GLCM is not ahead at the slowest speed ({slowest} mm/s), so it has no lead to shrink");
            Claim::judged(
                statement,
                Verdict::PointDisagrees,
                format!("{why}: {numbers}"),
            )
        } else {
            Claim::new(statement, margins.first() > margins.last(), numbers)
        };
        out.push(claim);
    }
    out
}

fn e2_claims(r: &Results) -> Vec<Claim> {
    let Some(e2) = r.e2.as_ref() else {
        return Vec::new();
    };
    let idx = |name: &str| e2.labels.iter().position(|l| l.eq_ignore_ascii_case(name));
    let (Some(rug), Some(sb), Some(stf)) = (idx("TRug"), idx("SB"), idx("STF")) else {
        return Vec::new();
    };
    let frac = |m: &Vec<Vec<usize>>, row: usize| {
        m[row][rug] as f64 / m[row].iter().sum::<usize>().max(1) as f64
    };
    let t = (frac(&e2.taxel, sb) + frac(&e2.taxel, stf)) / 2.0;
    let g = (frac(&e2.glcm3d, sb) + frac(&e2.glcm3d, stf)) / 2.0;
    let mut out = vec![Claim::new(
        "E2: the single taxel mistakes scotch brite and styrofoam for rug more than 3D-GLCM does",
        t > g,
        format!(
            "no test, the class chosen in error is not kept per recording, recognising SB and \
             STF is tested below; share of SB and STF predicted as TRug: single taxel {} %, \
             3D-GLCM {} %",
            pct(t),
            pct(g)
        ),
    )];
    let paired = &e2.glcm3d_vs_taxel_by_class;
    if let (Some(p_sb), Some(p_stf)) = (paired.get(sb), paired.get(stf)) {
        out.push(Claim::judged(
            "E2: 3D-GLCM recognises scotch brite and styrofoam better than the single taxel",
            Verdict::tested([p_sb.verdict, p_stf.verdict]),
            format!(
                "3D-GLCM minus single taxel on each class's recordings: SB {}; STF {}",
                difference(p_sb),
                difference(p_stf)
            ),
        ));
    }
    out
}

fn e3_claims(r: &Results) -> Vec<Claim> {
    let Some(e3) = r.e3.as_ref() else {
        return Vec::new();
    };
    let (Some(&last), Some(&n)) = (e3.mean.last(), e3.n.last()) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    // E3 moves taxels of the encoding as run; another encoding can differ by more.
    let encoding = r.encoder_sensitivity.as_ref().map_or(String::new(), |s| {
        match s.largest_spread > 0.0 {
            true => format!(
                ", the encoding as run (one encoding's accuracy differs from another's by up to {} points here)",
                pct(s.largest_spread)
            ),
            false => ", the encoding as run (every encoding gave the same accuracies here)".into(),
        }
    });
    if let Some(drop) = e3.unperturbed_vs_moved.last() {
        out.push(Claim::judged(
            "E3: moving taxels lowers 3D-GLCM accuracy",
            Verdict::tested([drop.verdict]),
            format!(
                "unperturbed {} %, {n} moved {} %: unperturbed minus moved {} on the same recordings{encoding}",
                pct(e3.glcm3d),
                pct(last),
                difference(drop)
            ),
        ));
    }
    let statement =
        "E3: with the most taxels moved, 3D-GLCM falls to the single taxel (within 5 points) or below";
    let numbers = format!(
        "{n} moved {} %, single taxel {} %",
        pct(last),
        pct(e3.taxel_mean)
    );
    out.push(if e3.glcm3d <= e3.taxel_mean + 0.05 {
        // Already there unperturbed: moving taxels cannot show the fall the claim is about.
        let why = format!(
            "3D-GLCM is not above the single taxel before any taxel moves (unperturbed {} %), so it has nothing to fall",
            pct(e3.glcm3d)
        );
        Claim::judged(statement, Verdict::NotJudged, format!("{why}: {numbers}"))
    } else {
        Claim::new(
            statement,
            last <= e3.taxel_mean + 0.05,
            format!("no test, a claim of similarity: {numbers}"),
        )
    });
    out
}

fn e4_claim(r: &Results) -> Option<Claim> {
    if r.e4.is_empty() {
        return None;
    }
    let verdicts =
        r.e4.values()
            .flat_map(|e| [e.taxel_vs_glcm2d.verdict, e.glcm3d_vs_glcm2d.verdict]);
    Some(Claim::judged(
        "E4: without time (2D-GLCM) accuracy falls below both the single taxel and 3D-GLCM",
        Verdict::tested(verdicts),
        r.e4.iter()
            .map(|(s, e)| {
                let (t, g) = (
                    difference(&e.taxel_vs_glcm2d),
                    difference(&e.glcm3d_vs_glcm2d),
                );
                format!(
                    "{s} mm/s: 2D {} %; single taxel {t}, 3D {g} above it",
                    pct(e.glcm2d)
                )
            })
            .collect::<Vec<_>>()
            .join("; "),
    ))
}

fn e5_claims(r: &Results) -> Vec<Claim> {
    if r.e5.is_empty() {
        return Vec::new();
    }
    let mut out = Vec::new();
    let paired: Vec<_> =
        r.e5.iter()
            .filter_map(|(s, e)| e.longest_vs_shortest.as_ref().map(|c| (s, c)))
            .collect();
    if !paired.is_empty() {
        out.push(Claim::judged(
            "E5: 3D-GLCM accuracy grows with the part of the slide used",
            Verdict::tested(paired.iter().map(|(_, c)| c.verdict)),
            paired
                .iter()
                .map(|(s, c)| {
                    format!(
                        "{s} mm/s: {} minus {}: {}",
                        c.first,
                        c.second,
                        difference(c)
                    )
                })
                .collect::<Vec<_>>()
                .join("; "),
        ));
    }
    out.push(Claim::new(
        "E5: 3D-GLCM matches the single taxel's full-slide accuracy with part of the slide",
        r.e5.values()
            .all(|e| e.first_match.is_some_and(|p| p < 1.0)),
        "no test, a claim of reaching a level: ".to_string()
            + &r.e5
                .iter()
                .map(|(s, e)| {
                    let at = e
                        .first_match
                        .map_or("never".to_string(), |p| format!("{:.0} %", 100.0 * p));
                    format!("{s} mm/s: {at}")
                })
                .collect::<Vec<_>>()
                .join("; "),
    ));
    out
}

fn e6_claim(r: &Results) -> Option<Claim> {
    if r.e6.is_empty() {
        return None;
    }
    Some(Claim::judged(
        "E6: trained on the other speeds, 3D-GLCM generalises to a held-out speed better than the single taxel",
        Verdict::tested(r.e6.values().map(|e| e.glcm3d_vs_taxel.verdict)),
        r.e6.iter()
            .map(|(s, e)| {
                let d = difference(&e.glcm3d_vs_taxel);
                format!("test {s} mm/s: {} vs {} %, {d}", pct(e.glcm3d), pct(e.taxel_mean))
            })
            .collect::<Vec<_>>()
            .join("; "),
    ))
}

fn e8_claim(r: &Results) -> Option<Claim> {
    if r.e8.is_empty() {
        return None;
    }
    // The k skipped at some speed (training folds too small), said beside the verdict; a
    // claim over every k says nothing on one.
    let mut skipped: Vec<usize> = r
        .skipped
        .keys()
        .filter_map(|key| key.strip_prefix("e8 k=")?.split(' ').next()?.parse().ok())
        .collect();
    skipped.sort_unstable();
    skipped.dedup();
    let ks = |list: &[usize]| {
        list.iter()
            .map(usize::to_string)
            .collect::<Vec<_>>()
            .join(", ")
    };
    let not_run = match skipped.is_empty() {
        true => String::new(),
        false => format!(
            "; k = {} not evaluated at every speed: their training folds are too small, as Skipped lists",
            ks(&skipped)
        ),
    };
    if r.e8.values().all(|e| e.k.len() < 2) {
        let evaluated: Vec<usize> = r.e8.values().flat_map(|e| e.k.clone()).collect();
        return Some(Claim::judged(
            "E8: 3D-GLCM stays ahead for every k",
            Verdict::NotJudged,
            format!(
                "a single k evaluated at each speed (k = {}){not_run}",
                ks(&evaluated)
            ),
        ));
    }
    let paired = r.e8.values().all(|e| e.glcm3d_vs_taxel.len() == e.k.len());
    if !paired {
        return Some(Claim::new(
            "E8: 3D-GLCM stays ahead for every k",
            r.e8.values()
                .all(|e| e.glcm3d.iter().zip(&e.taxel_mean).all(|(g, t)| g > t)),
            String::new(),
        ));
    }
    Some(Claim::judged(
        "E8: 3D-GLCM stays ahead for every k",
        Verdict::tested(
            r.e8.values()
                .flat_map(|e| e.glcm3d_vs_taxel.iter().map(|c| c.verdict)),
        ),
        r.e8.iter()
            .map(|(s, e)| {
                let per_k: Vec<String> =
                    e.k.iter()
                        .zip(&e.glcm3d_vs_taxel)
                        .map(|(k, c)| format!("k = {k}: {}", difference(c)))
                        .collect();
                format!("{s} mm/s: {}", per_k.join(", "))
            })
            .collect::<Vec<_>>()
            .join("; ")
            + &not_run,
    ))
}

#[cfg(test)]
mod tests {
    use super::super::testing::small_run;
    use super::super::{compare_shares, E5Speed, E8Speed, E2, E3};
    use super::*;
    use crate::values::Speed;
    use PairedVerdict::{Contradicted, NotShown, Supported};

    /// Results of the small run whose E2, E3, E5 and E8 carry `paired` as every paired
    /// comparison (and point values agreeing with the paper).
    fn results_with(paired: &Comparison) -> Results {
        let mut r = Results::empty(&small_run().prepared);
        let speed = Speed::of(10.0);
        let matrix = vec![vec![6, 0, 0], vec![3, 3, 0], vec![3, 0, 3]];
        r.e2 = Some(E2 {
            speed,
            labels: vec!["TRug".into(), "SB".into(), "STF".into()],
            taxel: matrix.clone(),
            glcm3d: vec![vec![6, 0, 0], vec![0, 6, 0], vec![0, 0, 6]],
            glcm3d_vs_taxel_by_class: vec![paired.clone(); 3],
        });
        r.e3 = Some(E3 {
            speed,
            repeats: 2,
            n: vec![4, 16],
            mean: vec![0.6, 0.4],
            std: vec![0.0, 0.0],
            interval: Vec::new(),
            glcm3d: 0.8,
            taxel_mean: 0.4,
            unperturbed_vs_moved: vec![paired.clone(); 2],
        });
        r.e5.insert(
            speed,
            E5Speed {
                fractions: vec![0.5, 1.0],
                glcm3d: vec![Some(0.5), Some(0.8)],
                glcm3d_interval: Vec::new(),
                taxel_full: 0.5,
                taxel_full_interval: None,
                first_match: Some(0.5),
                longest_vs_shortest: Some(paired.clone()),
            },
        );
        r.e8.insert(
            speed,
            E8Speed {
                k: vec![1, 5],
                encodings: 1,
                taxel_mean: vec![0.4, 0.4],
                glcm3d: vec![0.8, 0.8],
                taxel_mean_interval: Vec::new(),
                glcm3d_interval: Vec::new(),
                glcm3d_vs_taxel: vec![paired.clone(); 2],
            },
        );
        r
    }

    /// The verdicts of the tested claims of E2, E3, E5 and E8.
    fn tested_verdicts(r: &Results) -> Vec<(String, Verdict)> {
        claims(r)
            .into_iter()
            .filter(|c| {
                ["E2", "E3", "E5", "E8"]
                    .iter()
                    .any(|e| c.statement.starts_with(e))
            })
            .filter(|c| !matches!(c.verdict, Verdict::PointAgrees | Verdict::PointDisagrees))
            .map(|c| (c.statement, c.verdict))
            .collect()
    }

    #[test]
    fn paired_claims_hold_on_a_large_difference_not_on_a_tiny_one_and_fail_on_the_reverse() {
        let params = &small_run().params;
        let rows =
            |shares: Vec<f64>| -> Vec<(usize, f64)> { shares.into_iter().enumerate().collect() };
        let ones = rows(vec![0.9; 40]);
        let zeros = rows(vec![0.1; 40]);
        let half = rows((0..40).map(|i| f64::from(i % 2)).collect());
        let mut nudged = half.clone();
        nudged[0].1 = 1.0;
        let cases = [
            (
                compare_shares(("a", &ones), ("b", &zeros), params),
                Verdict::Holds,
            ),
            (
                compare_shares(("a", &nudged), ("b", &half), params),
                Verdict::NotShown,
            ),
            (
                compare_shares(("a", &zeros), ("b", &ones), params),
                Verdict::Contradicted,
            ),
        ];
        for (paired, expected) in cases {
            let verdicts = tested_verdicts(&results_with(&paired.unwrap()));
            // E2's recognition, E3's drop, E5's growth and E8's lead are tested
            assert_eq!(verdicts.len(), 4, "{verdicts:?}");
            for (statement, verdict) in verdicts {
                assert_eq!(verdict, expected, "{statement}");
            }
        }
    }

    #[test]
    fn a_lead_at_the_ceiling_or_on_one_k_is_not_judged_and_no_lead_cannot_shrink() {
        let run = small_run();
        let mut r = results_with(
            &compare_shares(
                ("a", &[(0, 1.0), (1, 1.0)]),
                ("b", &[(0, 0.0), (1, 0.0)]),
                &run.params,
            )
            .unwrap(),
        );
        r.e1 = super::super::e1_accuracy(&run.context()).unwrap();
        assert!(r.e1.len() >= 2, "the small run has two speeds");
        let lead = |r: &Results| {
            claims(r)
                .into_iter()
                .find(|c| c.statement.contains("lead over the single taxel shrinks"))
                .unwrap()
        };
        let set = |r: &mut Results, glcm3d: [f64; 2], taxel: [f64; 2]| {
            for (i, e) in r.e1.values_mut().enumerate() {
                (e.glcm3d, e.taxel_mean) = (glcm3d[i], taxel[i]);
            }
        };
        set(&mut r, [0.9, 0.7], [0.5, 0.5]);
        assert_eq!(lead(&r).verdict, Verdict::PointAgrees);
        set(&mut r, [1.0, 0.9], [0.5, 0.5]);
        let at_ceiling = lead(&r);
        assert_eq!(at_ceiling.verdict, Verdict::NotJudged);
        assert!(
            at_ceiling.detail.contains("ceiling"),
            "{}",
            at_ceiling.detail
        );
        // behind at both speeds, and less so at the fastest: no lead shrank
        set(&mut r, [0.3, 0.45], [0.5, 0.5]);
        let behind = lead(&r);
        assert_eq!(behind.verdict, Verdict::PointDisagrees);
        assert!(
            behind.detail.contains("no lead to shrink"),
            "{}",
            behind.detail
        );

        // E3 when 3D-GLCM starts at or below the single taxel: nothing to fall
        let e3 = r.e3.as_mut().unwrap();
        (e3.glcm3d, e3.taxel_mean) = (0.42, 0.45);
        let fall = claims(&r)
            .into_iter()
            .find(|c| c.statement.contains("falls to the single taxel"))
            .unwrap();
        assert_eq!(fall.verdict, Verdict::NotJudged);
        assert!(fall.detail.contains("nothing to fall"), "{}", fall.detail);

        // E8 with one k left at each speed, the others skipped
        for e in r.e8.values_mut() {
            e.k.truncate(1);
            e.glcm3d_vs_taxel.truncate(1);
        }
        r.skipped
            .insert("e8 k=5 at 10 mm/s".into(), "too few".into());
        let e8 = claims(&r)
            .into_iter()
            .find(|c| c.statement.starts_with("E8"))
            .unwrap();
        assert_eq!(e8.verdict, Verdict::NotJudged);
        assert!(e8.detail.contains("a single k") && e8.detail.contains("k = 5 not evaluated"));
    }

    #[test]
    fn a_tested_claim_holds_only_when_supported_everywhere() {
        assert_eq!(Verdict::tested([Supported, Supported]), Verdict::Holds);
        assert_eq!(Verdict::tested([Supported, NotShown]), Verdict::NotShown);
        assert_eq!(
            Verdict::tested([Supported, Contradicted]),
            Verdict::Contradicted
        );
        assert_eq!(Verdict::tested([]), Verdict::NotShown);
        assert!(Verdict::PointAgrees.holds() && !Verdict::NotShown.holds());
    }
}

//! The paper's conclusions judged on our results: each claim is a function of [`Results`]
//! that says whether the claim holds here and on which numbers. The report only prints them.

use serde::{Deserialize, Serialize};

use super::{Comparison, Results};
use crate::classify::PairedVerdict;

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
            Verdict::NotShown => "Not shown (within noise)",
            Verdict::Contradicted => "Contradicted (paired test)",
            Verdict::PointAgrees => "Agrees in point estimates (no test)",
            Verdict::PointDisagrees => "Disagrees in point estimates (no test)",
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
        "{:+.1} points [{:+.1}, {:+.1}]",
        100.0 * c.difference,
        100.0 * c.lower,
        100.0 * c.upper
    )
}

fn pct(a: f64) -> String {
    format!("{:.1}", 100.0 * a)
}

/// Every claim these results can judge, in the paper's order; a claim whose analysis was
/// skipped (or whose textures are absent) is left out.
pub fn claims(r: &Results) -> Vec<Claim> {
    let mut out = e1_claims(r);
    out.extend(e2_claim(r));
    out.extend(e3_claim(r));
    out.extend(e4_claim(r));
    out.extend(e5_claim(r));
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
        out.push(Claim::new(
            "E1: the margin shrinks from the slowest to the fastest speed",
            margins.first() > margins.last(),
            by_magnitude
                .iter()
                .zip(&margins)
                .map(|((s, _), m)| format!("{s} mm/s: {:+.1}", 100.0 * m))
                .collect::<Vec<_>>()
                .join(", ")
                + " points",
        ));
    }
    out
}

fn e2_claim(r: &Results) -> Option<Claim> {
    let e2 = r.e2.as_ref()?;
    let idx = |name: &str| e2.labels.iter().position(|l| l.eq_ignore_ascii_case(name));
    let (rug, sb, stf) = (idx("TRug")?, idx("SB")?, idx("STF")?);
    let frac = |m: &Vec<Vec<usize>>, row: usize| {
        m[row][rug] as f64 / m[row].iter().sum::<usize>().max(1) as f64
    };
    let t = (frac(&e2.taxel, sb) + frac(&e2.taxel, stf)) / 2.0;
    let g = (frac(&e2.glcm3d, sb) + frac(&e2.glcm3d, stf)) / 2.0;
    Some(Claim::new(
        "E2: the single taxel mistakes scotch brite and styrofoam for rug more than 3D-GLCM does",
        t > g,
        format!(
            "share of SB and STF predicted as TRug: single taxel {} %, 3D-GLCM {} %",
            pct(t),
            pct(g)
        ),
    ))
}

fn e3_claim(r: &Results) -> Option<Claim> {
    let e3 = r.e3.as_ref()?;
    let (&last, &n) = (e3.mean.last()?, e3.n.last()?);
    Some(Claim::new(
        "E3: moving taxels lowers 3D-GLCM accuracy towards or below the single taxel",
        last < e3.glcm3d && last <= e3.taxel_mean + 0.05,
        format!(
            "unperturbed {} %, {n} moved {} %, single taxel {} %",
            pct(e3.glcm3d),
            pct(last),
            pct(e3.taxel_mean)
        ),
    ))
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

fn e5_claim(r: &Results) -> Option<Claim> {
    if r.e5.is_empty() {
        return None;
    }
    Some(Claim::new(
        "E5: 3D-GLCM matches the single taxel's full-slide accuracy with part of the slide",
        r.e5.values()
            .all(|e| e.first_match.is_some_and(|p| p < 1.0)),
        r.e5.iter()
            .map(|(s, e)| {
                let at = e
                    .first_match
                    .map_or("never".to_string(), |p| format!("{:.0} %", 100.0 * p));
                format!("{s} mm/s: {at}")
            })
            .collect::<Vec<_>>()
            .join("; "),
    ))
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
    Some(Claim::new(
        "E8: 3D-GLCM stays ahead for every k",
        r.e8.values()
            .all(|e| e.glcm3d.iter().zip(&e.taxel_mean).all(|(g, t)| g > t)),
        String::new(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use PairedVerdict::{Contradicted, NotShown, Supported};

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

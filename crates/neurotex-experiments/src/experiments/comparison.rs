//! Uncertainty of the analyses' accuracies: a 95 % interval for each from a bootstrap over
//! recordings, and paired comparisons of two methods on the same recordings.
//!
//! Both resample recordings (Efron's percentile bootstrap), keeping each recording's
//! predictions over CV repeats, and over taxels for the single taxel, together: they are
//! not independent. A paired comparison takes, per recording, the difference between the
//! two methods' shares of right predictions, and asks whether the bootstrap interval of its
//! mean excludes 0. Unlike McNemar's test this works when a method's answer per recording is
//! a share (the mean over taxels), and it compares the methods on exactly the same folds.

use serde::{Deserialize, Serialize};

use super::ValidReproduceParams;
use crate::analysis::{seeded_bootstrap_over_encodings, Outcome};
use crate::classify::PairedVerdict;
use crate::error::{ClassifyError, Result};

/// Two methods compared on the same recordings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Comparison {
    /// The method expected to be better.
    pub first: String,
    /// The other method.
    pub second: String,
    /// Mean over recordings of the first's share of right predictions minus the second's.
    pub difference: f64,
    /// 95 % percentile-bootstrap interval of `difference`, lower end.
    pub lower: f64,
    /// Upper end.
    pub upper: f64,
    /// Supported when the interval lies above 0, contradicted when below, not shown when
    /// it holds 0.
    pub verdict: PairedVerdict,
    /// Recordings compared.
    pub recordings: usize,
}

/// `first` against `second`, evaluated on the same recordings.
///
/// # Errors
/// The outcomes were evaluated on different recordings.
pub fn compare(
    first: (&str, &Outcome),
    second: (&str, &Outcome),
    params: &ValidReproduceParams,
) -> Result<Comparison> {
    compare_encodings((first.0, &[first.1]), (second.0, &[second.1]), params)
}

/// `first` against `second` over several encodings of the same recordings: `first.1[e]`
/// and `second.1[e]` were evaluated on encoding `e`. The difference is the mean over
/// encodings and recordings, and its interval resamples both (one encoding per resample,
/// the same for the two methods, [`crate::classify::bootstrap_over_encodings`]); with one
/// encoding this is [`compare`].
///
/// # Errors
/// No encodings, different numbers of them, or outcomes on different recordings.
pub fn compare_encodings(
    first: (&str, &[&Outcome]),
    second: (&str, &[&Outcome]),
    params: &ValidReproduceParams,
) -> Result<Comparison> {
    let shares = |o: &[&Outcome]| -> Vec<Vec<(usize, f64)>> {
        o.iter().map(|o| o.correct_shares.clone()).collect()
    };
    paired(
        (first.0, &shares(first.1)),
        (second.0, &shares(second.1)),
        params,
    )
}

/// `first` against `second` from per-recording `(table row, share right)` lists, as
/// [`Outcome::correct_shares`] holds them; for analyses that pool several evaluations per
/// recording (E3's perturbation draws) or look at a subset of recordings (E2's classes).
///
/// # Errors
/// The lists name different recordings, or are empty.
pub fn compare_shares(
    first: (&str, &[(usize, f64)]),
    second: (&str, &[(usize, f64)]),
    params: &ValidReproduceParams,
) -> Result<Comparison> {
    paired(
        (first.0, &[first.1.to_vec()]),
        (second.0, &[second.1.to_vec()]),
        params,
    )
}

/// The paired comparison of per-recording shares under each encoding.
fn paired(
    first: (&str, &[Vec<(usize, f64)>]),
    second: (&str, &[Vec<(usize, f64)>]),
    params: &ValidReproduceParams,
) -> Result<Comparison> {
    let unpaired = || -> crate::Error {
        let (first, second) = (first.0.to_string(), second.0.to_string());
        ClassifyError::Unpaired { first, second }.into()
    };
    let (a, b) = (first.1, second.1);
    if a.len() != b.len() || a.is_empty() {
        return Err(unpaired());
    }
    let rows = |x: &[(usize, f64)]| x.iter().map(|r| r.0).collect::<Vec<_>>();
    let recordings = rows(&a[0]);
    if a.iter().chain(b).any(|x| rows(x) != recordings) {
        return Err(unpaired());
    }
    // The difference lies in [-1, 1]; the bootstrap takes shares in [0, 1], so it resamples
    // (d + 1) / 2 and the interval is mapped back, which is exact for a mean.
    let shifted: Vec<Vec<f64>> = a
        .iter()
        .zip(b)
        .map(|(a, b)| {
            a.iter()
                .zip(b)
                .map(|(x, y)| (x.1 - y.1 + 1.0) / 2.0)
                .collect()
        })
        .collect();
    let interval = seeded_bootstrap_over_encodings(&shifted, params.seed)?;
    let back = |v: f64| 2.0 * v - 1.0;
    let (lower, upper) = (back(interval.lower), back(interval.upper));
    let verdict = if lower > 0.0 {
        PairedVerdict::Supported
    } else if upper < 0.0 {
        PairedVerdict::Contradicted
    } else {
        PairedVerdict::NotShown
    };
    Ok(Comparison {
        first: first.0.to_string(),
        second: second.0.to_string(),
        difference: back(interval.estimate),
        lower,
        upper,
        verdict,
        recordings: recordings.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::super::testing::small_run;
    use super::*;

    fn outcome(shares: &[f64]) -> Outcome {
        let mut o = small_run()
            .tables
            .headline
            .values()
            .next()
            .unwrap()
            .glcm3d
            .clone();
        o.correct_shares = shares.iter().copied().enumerate().collect();
        o
    }

    #[test]
    fn clear_differences_are_supported_or_contradicted_and_equal_ones_not_shown() {
        let params = &small_run().params;
        let better = outcome(&[1.0; 40]);
        let worse = outcome(&[0.0; 40]);
        let mixed = outcome(&(0..40).map(|i| f64::from(i % 2)).collect::<Vec<_>>());
        let up = compare(("a", &better), ("b", &worse), params).unwrap();
        assert_eq!((up.difference, up.verdict), (1.0, PairedVerdict::Supported));
        let down = compare(("b", &worse), ("a", &better), params).unwrap();
        assert_eq!(
            (down.difference, down.verdict),
            (-1.0, PairedVerdict::Contradicted)
        );
        let same = compare(("m", &mixed), ("m2", &mixed), params).unwrap();
        assert_eq!(
            (same.difference, same.verdict),
            (0.0, PairedVerdict::NotShown)
        );
        let interval = mixed.accuracy_interval(params.seed).unwrap();
        assert_eq!(interval.estimate, 0.5);
        assert!(interval.lower < 0.5 && interval.upper > 0.5);
        // One encoding where the first wins on every recording, one where they tie: the
        // difference is half, but half the resamples see none, so it is not shown.
        let as_run = compare(("a", &better), ("b", &worse), params).unwrap();
        let tie = outcome(&[1.0; 40]);
        let over =
            compare_encodings(("a", &[&better, &tie]), ("b", &[&worse, &tie]), params).unwrap();
        assert_eq!(as_run.verdict, PairedVerdict::Supported);
        assert_eq!((over.difference, over.lower), (0.5, 0.0));
        assert_eq!(over.verdict, PairedVerdict::NotShown);
        let single = compare_encodings(("a", &[&better]), ("b", &[&worse]), params).unwrap();
        assert_eq!(single, as_run);
        assert!(compare_encodings(("a", &[&better, &tie]), ("b", &[&worse]), params).is_err());
        let unpaired = compare(("a", &better), ("short", &outcome(&[1.0; 3])), params);
        assert!(matches!(
            unpaired,
            Err(crate::Error::Classify(ClassifyError::Unpaired { .. }))
        ));
    }
}

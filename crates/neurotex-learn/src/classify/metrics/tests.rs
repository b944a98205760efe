use super::*;
use crate::classify::stats::StatsError;

#[test]
fn metrics_by_hand_with_an_absent_and_an_unpredicted_class() {
    // Class 2 never occurs in the truth but is predicted once; class 1 is never predicted.
    let m = ConfusionMatrix::from_predictions(&[0, 0, 0, 1, 1], &[0, 0, 2, 0, 0], 3);
    let metrics = Metrics::from_confusion(&m);
    assert_eq!((metrics.n, metrics.correct), (5, 2));
    assert!((metrics.accuracy - 0.4).abs() < 1e-15);
    // Recalls 2/3 and 0 over the 2 classes present.
    assert!((metrics.balanced_accuracy - 1.0 / 3.0).abs() < 1e-15);
    assert_eq!(metrics.classes_present, 2);
    assert!((metrics.chance_majority - 0.6).abs() < 1e-15);
    assert_eq!(metrics.chance_uniform, 0.5);
    assert_eq!(metrics.per_class[1].precision, None);
    assert_eq!(metrics.per_class[1].recall, Some(0.0));
    assert_eq!(metrics.per_class[2].recall, None);
    assert_eq!(metrics.per_class[2].precision, Some(0.0));
    assert_eq!(metrics.per_class[0].precision, Some(0.5));
    let json = serde_json::to_value(&metrics).unwrap();
    assert!(json["per_class"][1]["precision"].is_null());
}

#[test]
fn metrics_of_an_empty_matrix_are_zero() {
    let metrics = Metrics::from_confusion(&ConfusionMatrix::zeros(2));
    assert_eq!(metrics.n, 0);
    assert_eq!(metrics.accuracy, 0.0);
    assert_eq!(metrics.balanced_accuracy, 0.0);
    assert_eq!(metrics.chance_uniform, 0.0);
    assert_eq!(metrics.classes_present, 0);
}

#[test]
fn wilson_is_exact_at_the_ends_and_rejects_bad_counts() {
    let none = wilson_interval(0, 10).unwrap();
    assert_eq!((none.lower, none.estimate), (0.0, 0.0));
    assert!(none.upper > 0.2);
    let json = serde_json::to_value(&none).unwrap();
    assert_eq!(
        (json["method"].as_str(), json["n"].as_u64()),
        (Some("wilson"), Some(10))
    );
    assert_eq!(serde_json::from_value::<Interval>(json).unwrap(), none);
    let all = wilson_interval(10, 10).unwrap();
    assert_eq!((all.estimate, all.upper), (1.0, 1.0));
    assert!(all.lower < 0.8);
    assert_eq!(
        wilson_interval(0, 0),
        Err(StatsError::Empty {
            what: "predictions"
        })
    );
    assert!(matches!(
        wilson_interval(3, 2),
        Err(StatsError::CountAboveTotal { correct: 3, n: 2 })
    ));
}

#[test]
fn bootstrap_rule_and_errors() {
    assert!(BootstrapParams {
        resamples: 0,
        seed: 1
    }
    .check()
    .is_err());
    let params = BootstrapParams::default().check().unwrap();
    assert_eq!(params.resamples, 2000);
    assert!(matches!(
        bootstrap_accuracy(&[], &params),
        Err(StatsError::Empty { .. })
    ));
    assert!(matches!(
        bootstrap_mean_share(&[0.5, 1.5], &params),
        Err(StatsError::NotAnAccuracy { index: 1, .. })
    ));
    let one = bootstrap_accuracy(&[true], &params).unwrap();
    assert_eq!((one.lower, one.estimate, one.upper), (1.0, 1.0, 1.0));
}

#[test]
fn a_bootstrap_point_at_the_bounds_becomes_the_wilson_interval() {
    let params = BootstrapParams::default().check().unwrap();
    // 12 of 12 right: every resample is 100 %. Wilson's lower bound at k = n is
    // n / (n + z²) = 12 / (12 + 1.959964²) = 0.757506 (by hand).
    let all = bootstrap_accuracy(&[true; 12], &params).unwrap();
    assert_eq!((all.lower, all.upper), (1.0, 1.0));
    let all = all.or_wilson_at_the_bounds(12);
    assert!((all.lower - 0.757_506).abs() < 1e-6, "{all:?}");
    assert_eq!(all.upper, 1.0);
    assert_eq!(all.described(), "Wilson score over 12 recordings");
    let none = bootstrap_accuracy(&[false; 12], &params).unwrap();
    let none = none.or_wilson_at_the_bounds(12);
    assert_eq!(none.lower, 0.0);
    assert!((none.upper - (1.0 - 0.757_506)).abs() < 1e-6, "{none:?}");
    // An interval with spread is kept as it is.
    let mixed = bootstrap_accuracy(&[true, false, true, true], &params).unwrap();
    assert_eq!(mixed.clone().or_wilson_at_the_bounds(4), mixed);
}

#[test]
fn bootstrap_width_is_near_the_binomial_one() {
    // 80 of 100 correct: the bootstrap distribution is Binomial(100, 0.8) / 100, whose
    // 2.5 % and 97.5 % quantiles are 0.72 and 0.88 (scipy `binom.ppf`); 2000 resamples
    // land within a count of them.
    let correct: Vec<bool> = (0..100).map(|i| i < 80).collect();
    let params = BootstrapParams::default().check().unwrap();
    let interval = bootstrap_accuracy(&correct, &params).unwrap();
    assert_eq!(interval.estimate, 0.8);
    assert!((interval.lower - 0.72).abs() <= 0.011, "{interval:?}");
    assert!((interval.upper - 0.88).abs() <= 0.011, "{interval:?}");
}

#[test]
fn one_encoding_is_the_recordings_bootstrap_and_several_widen_it_to_their_mixture() {
    let params = BootstrapParams::default().check().unwrap();
    let share = |k: usize| {
        (0..100)
            .map(|i| f64::from(u8::from(i < k)))
            .collect::<Vec<_>>()
    };
    let alone = bootstrap_mean_share(&share(80), &params).unwrap();
    assert_eq!(
        bootstrap_over_encodings(&[share(80)], &params).unwrap(),
        alone
    );
    // Encodings giving 80 and 60 of 100: each resample is Binomial(100, 0.8) / 100 or
    // Binomial(100, 0.6) / 100 with equal odds, and that mixture's 2.5 % and 97.5 %
    // quantiles are 0.52 and 0.86 (the binomial sums in exact arithmetic); 2000
    // resamples land within a count or two of them.
    let both = bootstrap_over_encodings(&[share(80), share(60)], &params).unwrap();
    assert_eq!(both.estimate, 0.7);
    assert!((both.lower - 0.52).abs() <= 0.021, "{both:?}");
    assert!((both.upper - 0.86).abs() <= 0.021, "{both:?}");
    assert!(both.upper - both.lower > 2.0 * (alone.upper - alone.lower));
    assert!(matches!(
        both.method,
        IntervalMethod::EncodingBootstrap {
            n: 100,
            encodings: 2,
            ..
        }
    ));
    assert!(bootstrap_over_encodings(&[], &params).is_err());
    assert_eq!(
        bootstrap_over_encodings(&[share(80), vec![1.0; 3]], &params),
        Err(StatsError::LengthMismatch {
            first: 100,
            second: 3
        })
    );
    assert!(bootstrap_over_encodings(&[share(80), vec![2.0; 100]], &params).is_err());
}

#[test]
fn t_interval_errors_and_clipping() {
    assert_eq!(
        t_interval_over_repeats(&[0.5]),
        Err(StatsError::TooFewRepeats { got: 1 })
    );
    assert!(matches!(
        t_interval_over_repeats(&[0.5, f64::NAN]),
        Err(StatsError::NotAnAccuracy { index: 1, .. })
    ));
    let equal = t_interval_over_repeats(&[0.75, 0.75, 0.75]).unwrap();
    assert_eq!((equal.lower, equal.upper), (0.75, 0.75));
    let wide = t_interval_over_repeats(&[1.0, 0.5]).unwrap();
    assert_eq!(wide.upper, 1.0);
    assert_eq!(
        wide.method,
        IntervalMethod::StudentT {
            repeats: 2,
            clipped: true
        }
    );
}

#[test]
fn mcnemar_counts_winner_and_verdicts() {
    let first = [true, true, true, true, true, true, true, false, true];
    let second = [false, false, false, false, false, false, false, false, true];
    let test = mcnemar_exact(&first, &second).unwrap();
    assert_eq!((test.n, test.b, test.c), (9, 7, 0));
    // 2 · 2^-7
    assert_eq!(test.p_value, 1.0 / 64.0);
    assert_eq!(test.winner, Some(Side::First));
    assert_eq!(test.verdict(Side::First), PairedVerdict::Supported);
    assert_eq!(test.verdict(Side::Second), PairedVerdict::Contradicted);
    let weak = mcnemar_exact(&first[..3], &second[..3]).unwrap();
    assert_eq!(weak.p_value, 0.25);
    assert_eq!(weak.verdict(Side::First), PairedVerdict::NotShown);
    let none = mcnemar_exact(&[], &[]).unwrap();
    assert_eq!((none.p_value, none.winner), (1.0, None));
    assert_eq!(none.verdict(Side::Second), PairedVerdict::NotShown);
    assert_eq!(
        mcnemar_exact(&[true], &[]),
        Err(StatsError::LengthMismatch {
            first: 1,
            second: 0
        })
    );
    assert_eq!(Side::First.other(), Side::Second);
}

#[test]
fn an_interval_against_chance_by_hand() {
    use AgainstChance::{Below, Includes};
    for (ci, at) in [
        ([0.1, 0.2], Some(Below)),
        ([0.2, 0.3], Some(Includes)),
        ([0.25, 0.3], Some(Includes)),
        ([0.26, 0.3], None),
    ] {
        assert_eq!(AgainstChance::of(ci, 0.25), at, "{ci:?}");
    }
    // An edge at chance but for rounding is at it.
    let third = AgainstChance::of([0.333_333_333_333_333_37, 0.5], 1.0 / 3.0);
    assert_eq!(third, Some(AgainstChance::Includes));
}

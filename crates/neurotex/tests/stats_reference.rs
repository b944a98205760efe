//! neurotex's metrics, intervals and paired test against established tools, stored in
//! `tests/data/stats_reference.json` by `tests/reference/make_stats_reference.py` (tool
//! versions in its `provenance`: statsmodels, scipy, numpy, scikit-learn), then properties
//! on random inputs (proptest) and an exact-integer reference for the binomial tail.
//!
//! Tolerances. Counts, balanced accuracy, recall and precision are ratios of small
//! integers, computed the same way on both sides: within 1e-15. Everything else is compared
//! at 1e-12 relative: both sides compute the same closed forms or converge to the last bits
//! (Wilson, the t quantile, the binomial tail) but in a different order of operations, so
//! they agree closely, not bit for bit. Measured worst cases: Wilson 2e-15, t interval and
//! percentiles 4e-16, McNemar and the binomial tail 4e-14 (scipy's own error: see below),
//! the t quantile 4e-14 at p = 0.975 and 3e-13 at p = 0.999 with 999 degrees of freedom.
//! 1e-12 leaves room for another platform's `ln`/`exp`/`tan` and still catches any slip of
//! formula, which moves values in the third digit. A reference value of exactly 0 or 1 (an
//! interval's end at k = 0 or k = n, a p-value of 1) must be met exactly. The binomial
//! tails (McNemar's p-values) are also stored exactly (Python's integers and fractions) and
//! checked against those more tightly ([`exact_tolerance`]): scipy's own values are off by
//! up to 4e-14 at n = 2500.

use neurotex::classify::stats::{binomial_half_cdf, percentile, student_t_quantile, Z_95};
use neurotex::classify::{
    bootstrap_accuracy, mcnemar_exact, mcnemar_exact_p, t_interval_over_repeats, wilson_interval,
    BootstrapParams, ConfusionMatrix, Metrics, Side,
};
use proptest::prelude::*;
use serde_json::Value;

/// Relative tolerance for values that are not small-integer ratios (see the module doc).
const REL: f64 = 1e-12;

/// Tolerance against binomial tails computed in exact rational arithmetic (the `exact`
/// fields, and exact integers in the property test): only neurotex's own rounding counts.
/// The tail is computed through its logarithm, whose rounding, about 1e-16 · |ln P| in
/// absolute terms, becomes relative error in P; hence a bound that grows with |ln P|.
fn exact_tolerance(exact: f64) -> f64 {
    1e-15 * (2.0 + exact.ln().abs()) * exact
}

fn reference() -> Value {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/stats_reference.json"
    ))
    .expect("stats_reference.json is in the repository");
    serde_json::from_str(&text).expect("valid JSON")
}

fn cases<'a>(r: &'a Value, key: &str) -> &'a [Value] {
    r[key].as_array().expect("an array of cases")
}

fn uint(v: &Value) -> usize {
    v.as_u64().expect("a count") as usize
}

fn float(v: &Value) -> f64 {
    v.as_f64().expect("a number")
}

fn f64s(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(float).collect()
}

/// `got` within `rel` of `want` relatively; exactly equal when `want` is 0 or 1.
fn assert_close(got: f64, want: f64, rel: f64, what: &str) {
    if want == 0.0 || want == 1.0 {
        assert_eq!(got, want, "{what}");
    } else {
        assert!(
            (got - want).abs() <= rel * want.abs(),
            "{what}: got {got}, want {want}, relative error {:e}",
            (got - want).abs() / want.abs()
        );
    }
}

#[test]
fn z_is_scipys_normal_quantile() {
    assert_eq!(Z_95, float(&reference()["norm_ppf_975"]));
}

#[test]
fn wilson_matches_statsmodels() {
    let r = reference();
    for case in cases(&r, "wilson") {
        let (k, n) = (uint(&case["correct"]), uint(&case["n"]));
        let interval = wilson_interval(k, n).unwrap();
        let what = format!("wilson {k}/{n}");
        assert_close(interval.lower, float(&case["lower"]), REL, &what);
        assert_close(interval.upper, float(&case["upper"]), REL, &what);
        assert_eq!(interval.estimate, k as f64 / n as f64);
    }
}

#[test]
fn mcnemar_matches_statsmodels_exact() {
    let r = reference();
    for case in cases(&r, "mcnemar") {
        let (b, c) = (uint(&case["b"]), uint(&case["c"]));
        let want = float(&case["p_value"]);
        assert_close(
            mcnemar_exact_p(b, c),
            want,
            REL,
            &format!("mcnemar {b}, {c}"),
        );
        // The same through per-recording correctness, with concordant recordings added.
        let mut first = vec![true; b];
        first.extend(std::iter::repeat_n(false, c));
        let mut second: Vec<bool> = first.iter().map(|x| !x).collect();
        first.extend([true, true, false]);
        second.extend([true, true, false]);
        let test = mcnemar_exact(&first, &second).unwrap();
        assert_eq!((test.b, test.c, test.n), (b, c, b + c + 3));
        assert_eq!(test.p_value, mcnemar_exact_p(b, c));
    }
}

#[test]
fn binomial_tail_matches_scipy() {
    let r = reference();
    for case in cases(&r, "binom_half_cdf") {
        let (k, n) = (uint(&case["k"]), uint(&case["n"]));
        let what = format!("binom.cdf({k}, {n}, 0.5)");
        assert_close(binomial_half_cdf(k, n), float(&case["cdf"]), REL, &what);
        let (got, exact) = (binomial_half_cdf(k, n), float(&case["exact"]));
        assert!(
            (got - exact).abs() <= exact_tolerance(exact),
            "{what}: {got} {exact}"
        );
    }
}

#[test]
fn t_quantile_matches_scipy() {
    let r = reference();
    for case in cases(&r, "t_ppf") {
        let (p, dof) = (float(&case["p"]), uint(&case["dof"]));
        let got = student_t_quantile(p, dof).unwrap();
        assert_close(
            got,
            float(&case["quantile"]),
            REL,
            &format!("t.ppf({p}, {dof})"),
        );
    }
}

#[test]
fn t_interval_matches_scipy() {
    let r = reference();
    for case in cases(&r, "t_interval") {
        let per_repeat = f64s(&case["per_repeat"]);
        let interval = t_interval_over_repeats(&per_repeat).unwrap();
        let what = format!("t interval of {per_repeat:?}");
        assert_close(interval.estimate, float(&case["estimate"]), REL, &what);
        assert_close(interval.lower, float(&case["lower"]), REL, &what);
        assert_close(interval.upper, float(&case["upper"]), REL, &what);
    }
}

#[test]
fn percentile_matches_numpy() {
    let r = reference();
    for case in cases(&r, "percentile") {
        let sorted = f64s(&case["sorted"]);
        for (q, want) in f64s(&case["q"]).into_iter().zip(f64s(&case["value"])) {
            let what = format!("percentile {q} of {} values", sorted.len());
            assert_close(percentile(&sorted, q), want, REL, &what);
        }
    }
}

#[test]
fn metrics_match_scikit_learn() {
    let r = reference();
    for case in cases(&r, "sklearn_metrics") {
        let truth: Vec<usize> = case["truth"].as_array().unwrap().iter().map(uint).collect();
        let predicted: Vec<usize> = case["predicted"]
            .as_array()
            .unwrap()
            .iter()
            .map(uint)
            .collect();
        let matrix =
            ConfusionMatrix::from_predictions(&truth, &predicted, uint(&case["n_classes"]));
        let metrics = Metrics::from_confusion(&matrix);
        assert!((metrics.accuracy - float(&case["accuracy"])).abs() <= 1e-15);
        assert!((metrics.balanced_accuracy - float(&case["balanced_accuracy"])).abs() <= 1e-15);
        for (class, got) in metrics.per_class.iter().enumerate() {
            for (mine, key) in [(got.precision, "precision"), (got.recall, "recall")] {
                match (mine, case[key][class].as_f64()) {
                    (Some(a), Some(b)) => assert!((a - b).abs() <= 1e-15, "{key} {class}"),
                    (None, None) => {}
                    other => panic!("{key} of class {class}: {other:?}"),
                }
            }
        }
    }
}

/// `P(X <= k)` for `X ~ Binomial(n, 1/2)` from exact integer sums (n <= 120 fits a u128):
/// only the final division rounds.
fn exact_binomial_half_cdf(k: usize, n: usize) -> f64 {
    let mut choose: u128 = 1;
    let mut total: u128 = 0;
    for i in 0..=k.min(n) {
        total += choose;
        choose = choose * (n - i) as u128 / (i + 1) as u128;
    }
    total as f64 / 2f64.powi(n as i32)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn binomial_tail_matches_exact_integers(n in 0usize..=120, k_share in 0.0f64..=1.0) {
        let k = (k_share * n as f64) as usize;
        let exact = exact_binomial_half_cdf(k, n);
        let got = binomial_half_cdf(k, n);
        let error = (got - exact).abs();
        prop_assert!(error <= exact_tolerance(exact), "{}/{}: {} {}", k, n, got, exact);
    }

    #[test]
    fn wilson_contains_the_estimate_inside_0_1(n in 1usize..20_000, k_share in 0.0f64..=1.0) {
        let k = ((k_share * n as f64) as usize).min(n);
        let i = wilson_interval(k, n).unwrap();
        prop_assert!(0.0 <= i.lower && i.lower <= i.estimate, "{:?}", i);
        prop_assert!(i.estimate <= i.upper && i.upper <= 1.0, "{:?}", i);
        prop_assert!(i.lower < i.upper);
    }

    #[test]
    fn bootstrap_is_deterministic_and_contains_the_estimate(
        correct in proptest::collection::vec(any::<bool>(), 1..150),
        seed in any::<u64>(),
        resamples in 200usize..400,
    ) {
        let params = BootstrapParams { resamples, seed }.check().unwrap();
        let once = bootstrap_accuracy(&correct, &params).unwrap();
        let again = bootstrap_accuracy(&correct, &params).unwrap();
        prop_assert_eq!(&once, &again);
        prop_assert!(0.0 <= once.lower && once.lower <= once.estimate, "{:?}", once);
        prop_assert!(once.estimate <= once.upper && once.upper <= 1.0, "{:?}", once);
    }

    #[test]
    fn t_interval_contains_the_mean_inside_0_1(
        per_repeat in proptest::collection::vec(0.0f64..=1.0, 2..30),
    ) {
        let i = t_interval_over_repeats(&per_repeat).unwrap();
        prop_assert!(0.0 <= i.lower && i.lower <= i.estimate, "{:?}", i);
        prop_assert!(i.estimate <= i.upper && i.upper <= 1.0, "{:?}", i);
    }

    #[test]
    fn mcnemar_is_symmetric_in_the_methods(
        pairs in proptest::collection::vec(any::<(bool, bool)>(), 0..300),
    ) {
        let (first, second): (Vec<bool>, Vec<bool>) = pairs.into_iter().unzip();
        let ab = mcnemar_exact(&first, &second).unwrap();
        let ba = mcnemar_exact(&second, &first).unwrap();
        prop_assert_eq!(ab.p_value, ba.p_value);
        prop_assert_eq!((ab.b, ab.c), (ba.c, ba.b));
        prop_assert_eq!(ab.winner.map(Side::other), ba.winner);
        prop_assert!(ab.p_value > 0.0 && ab.p_value <= 1.0);
    }

    #[test]
    fn mcnemar_p_is_symmetric_for_large_counts(b in 0usize..5000, c in 0usize..5000) {
        prop_assert_eq!(mcnemar_exact_p(b, c), mcnemar_exact_p(c, b));
        prop_assert!((0.0..=1.0).contains(&mcnemar_exact_p(b, c)));
    }
}

/// `sign_flip_p` against scipy's `permutation_test` (paired, `permutation_type="samples"`),
/// stored in `tests/data/sign_flip_reference.json` by `tests/reference/make_sign_flip_reference.py`:
/// every sign pattern enumerated on both sides up to 16 units (equal to 1e-12), and within
/// five standard errors of sampling (both sides draw 400 000 patterns) beyond.
#[test]
fn sign_flip_p_values_match_scipy() {
    use neurotex::classify::metrics::sign_flip_p;
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/sign_flip_reference.json"
    ))
    .unwrap();
    let reference: Value = serde_json::from_str(&text).unwrap();
    let differences = |case: &Value| -> Vec<f64> {
        let values = case["differences"].as_array().unwrap();
        values.iter().map(|v| v.as_f64().unwrap()).collect()
    };
    for case in reference["exact"].as_array().unwrap() {
        let (d, want) = (differences(case), case["p"].as_f64().unwrap());
        let got = sign_flip_p(&d, 0, 0).unwrap();
        assert!((got - want).abs() <= 1e-12, "{d:?}: {got} vs scipy {want}");
    }
    for case in reference["sampled"].as_array().unwrap() {
        let (d, want) = (differences(case), case["p"].as_f64().unwrap());
        let resamples = case["resamples"].as_u64().unwrap() as usize;
        let got = sign_flip_p(&d, resamples, 7).unwrap();
        let se = (2.0 * want * (1.0 - want) / resamples as f64).sqrt();
        assert!(
            (got - want).abs() <= 5.0 * se + 1e-6,
            "n {}: {got} vs scipy {want}",
            d.len()
        );
    }
    assert!(sign_flip_p(&[], 100, 0).is_err());
    assert!(sign_flip_p(&[0.5, 1.5], 100, 0).is_err());
    assert!(sign_flip_p(&[0.5; 20], 0, 0).is_err());
}

//! Statistics of one taxel's conditioned signal, a hand-made baseline without spikes:
//! the first four moments, three quantiles, and the rate of the derivative's zero
//! crossings (how often the signal turns, a crude measure of its dominant frequency).

/// The names of [`signal_stats`]'s values, in order.
pub const SIGNAL_STAT_NAMES: [&str; 8] = [
    "mean",
    "std",
    "skewness",
    "kurtosis",
    "q10",
    "q50",
    "q90",
    "turns_per_s",
];

/// [`SIGNAL_STAT_NAMES`] of `x`, sampled at 1 kHz: the mean; the population standard
/// deviation; skewness and excess kurtosis from the population moments (0 for a constant
/// signal); the 10th, 50th and 90th percentiles by linear interpolation between order
/// statistics (numpy's default); and the sign changes of the first difference per second,
/// steps where the difference is exactly 0 skipped.
///
/// # Panics
/// If `x` is empty.
pub fn signal_stats(x: &[f64]) -> [f64; 8] {
    assert!(!x.is_empty());
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    let moment = |p: i32| x.iter().map(|v| (v - mean).powi(p)).sum::<f64>() / n;
    let var = moment(2);
    let std = var.sqrt();
    let (skew, kurt) = if var > 0.0 {
        (moment(3) / var.powf(1.5), moment(4) / (var * var) - 3.0)
    } else {
        (0.0, 0.0)
    };
    // Order statistics by selection rather than a full sort (a minute-long slide has
    // 60 000 samples per taxel), each selection on the part above the previous rank;
    // `scratch[from..]` holds the order statistics from `from` on, so the one right above
    // a selected rank is the smallest of that part (a scan, not another selection).
    let last = x.len() - 1;
    let positions = [0.1, 0.5, 0.9].map(|q| q * last as f64);
    let mut ranks: Vec<usize> = positions
        .iter()
        .flat_map(|p| [p.floor() as usize, (p.floor() as usize + 1).min(last)])
        .collect();
    ranks.sort_unstable();
    ranks.dedup();
    let mut scratch = x.to_vec();
    let mut at = vec![0.0; ranks.len()];
    let mut from = 0;
    for (value, &rank) in at.iter_mut().zip(&ranks) {
        let rest = &mut scratch[from..];
        if rank == from {
            let smallest = |a: f64, &b: &f64| if b.total_cmp(&a).is_lt() { b } else { a };
            *value = rest[1..].iter().fold(rest[0], smallest);
            continue;
        }
        let (_, v, _) = rest.select_nth_unstable_by(rank - from, f64::total_cmp);
        *value = *v;
        from = rank + 1;
    }
    let order = |rank: usize| at[ranks.binary_search(&rank).unwrap_or(0)];
    let quantiles = positions.map(|pos| {
        let lo = pos.floor() as usize;
        let low = order(lo);
        low + pos.fract() * (order((lo + 1).min(last)) - low)
    });
    let mut turns = 0usize;
    let mut last = 0.0f64;
    for w in x.windows(2) {
        let d = w[1] - w[0];
        if d != 0.0 {
            if last != 0.0 && (d > 0.0) != (last > 0.0) {
                turns += 1;
            }
            last = d;
        }
    }
    [
        mean,
        std,
        skew,
        kurt,
        quantiles[0],
        quantiles[1],
        quantiles[2],
        turns as f64 / (n / 1000.0),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_match_a_hand_calculation() {
        // x = 0, 2, 1, 3, 1 (1 kHz, 5 ms): mean 7/5 = 1.4; deviations -1.4, 0.6, -0.4, 1.6,
        // -0.4; m2 = (1.96 + 0.36 + 0.16 + 2.56 + 0.16) / 5 = 1.04; m3 = (-2.744 + 0.216
        // - 0.064 + 4.096 - 0.064) / 5 = 0.288; m4 = (3.8416 + 0.1296 + 0.0256 + 6.5536
        // + 0.0256) / 5 = 2.1152. Sorted 0, 1, 1, 2, 3: q10 at 0.4 -> 0.4, q50 -> 1,
        // q90 at 3.6 -> 2.6. Differences +2, -1, +2, -2: 3 turns in 5 ms = 600 per s.
        let s = signal_stats(&[0.0, 2.0, 1.0, 3.0, 1.0]);
        let expect = [
            1.4,
            1.04f64.sqrt(),
            0.288 / 1.04f64.powf(1.5),
            2.1152 / (1.04 * 1.04) - 3.0,
            0.4,
            1.0,
            2.6,
            600.0,
        ];
        for (g, e) in s.iter().zip(&expect) {
            assert!((g - e).abs() < 1e-9, "{s:?} vs {expect:?}");
        }
    }

    #[test]
    fn quantiles_by_selection_equal_those_of_the_sorted_signal() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        for len in [1usize, 2, 3, 10, 11, 101, 1000] {
            let x: Vec<f64> = (0..len)
                .map(|_| {
                    state ^= state << 13;
                    state ^= state >> 7;
                    state ^= state << 17;
                    // Few distinct values: ties among the order statistics.
                    (state >> 60) as f64
                })
                .collect();
            let mut sorted = x.clone();
            sorted.sort_by(f64::total_cmp);
            let at = |q: f64| {
                let pos = q * (len - 1) as f64;
                let lo = pos.floor() as usize;
                let hi = (lo + 1).min(len - 1);
                sorted[lo] + pos.fract() * (sorted[hi] - sorted[lo])
            };
            let s = signal_stats(&x);
            assert_eq!([s[4], s[5], s[6]], [at(0.1), at(0.5), at(0.9)], "{len}");
        }
    }

    #[test]
    fn a_constant_signal_has_no_spread_and_no_turns() {
        let s = signal_stats(&[0.5; 10]);
        assert_eq!(s, [0.5, 0.0, 0.0, 0.0, 0.5, 0.5, 0.5, 0.0]);
    }
}

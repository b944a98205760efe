//! The units a comparison's intervals and paired tests resample.

use super::{mean, Candidate, CompareParams, Protocol, Ranked, Scored};
use crate::classify::draws::for_each_resample;
use crate::classify::metrics::sign_flip_p;
use crate::classify::stats::percentile;
use crate::classify::wilson_at_the_bounds;
use crate::error::{ClassifyError, Result};
use crate::recording::Meta;

/// The units intervals and tests resample: per evaluated row, its unit; units grouped by
/// condition (one condition unless the protocol has several).
pub(super) struct Units {
    /// Each evaluated row's unit index, in the order of the scored shares.
    pub(super) unit_of: Vec<usize>,
    /// Each condition's units.
    by_condition: Vec<Vec<usize>>,
    n_units: usize,
    resamples: usize,
    seed: u64,
}

impl Units {
    pub(super) fn new(
        metas: &[Meta],
        shares: &[(usize, f64)],
        params: &CompareParams,
    ) -> Result<Units> {
        let condition_column = match &params.protocol {
            Protocol::Per(c) | Protocol::HoldOut(c) => Some(c.as_str()),
            _ => None,
        };
        let key = |row: usize| {
            let meta = &metas[row];
            let condition = condition_column
                .and_then(|c| meta.field(c))
                .unwrap_or_default();
            let unit = match &params.group_by {
                Some(column) => meta.field(column).unwrap_or_default(),
                None => meta.file.clone(),
            };
            (condition, unit)
        };
        let mut keys: Vec<(String, String)> = Vec::new();
        let mut unit_of = Vec::with_capacity(shares.len());
        for &(row, _) in shares {
            let k = key(row);
            let index = keys.iter().position(|x| *x == k).unwrap_or_else(|| {
                keys.push(k);
                keys.len() - 1
            });
            unit_of.push(index);
        }
        let mut names: Vec<&String> = Vec::new();
        let mut by_condition: Vec<Vec<usize>> = Vec::new();
        for (u, (condition, _)) in keys.iter().enumerate() {
            match names.iter().position(|n| *n == condition) {
                Some(i) => by_condition[i].push(u),
                None => {
                    names.push(condition);
                    by_condition.push(vec![u]);
                }
            }
        }
        Ok(Units {
            unit_of,
            by_condition,
            n_units: keys.len(),
            resamples: params.resamples,
            seed: params.cv.seed,
        })
    }

    pub(super) fn n_units(&self) -> usize {
        self.n_units
    }

    /// Per unit, the sum of its rows' shares and its row count.
    fn totals(&self, shares: &[(usize, f64)]) -> Vec<(f64, usize)> {
        let mut totals = vec![(0.0, 0usize); self.n_units];
        for (&(_, s), &u) in shares.iter().zip(&self.unit_of) {
            totals[u].0 += s;
            totals[u].1 += 1;
        }
        totals
    }

    /// The 95 % interval of the mean over conditions of the row-weighted mean share, by a
    /// percentile bootstrap resampling units within each condition.
    pub(super) fn interval(&self, shares: &[(usize, f64)]) -> [f64; 2] {
        let totals = self.totals(shares);
        let sizes: Vec<usize> = self.by_condition.iter().map(Vec::len).collect();
        let rounds = self.resamples.max(1);
        let mut means: Vec<f64> = Vec::with_capacity(rounds);
        for_each_resample(self.seed, &sizes, rounds, |picked| {
            means.push(self.resampled_mean(&totals, picked));
        });
        self.percentiles(means)
    }

    /// [`Units::interval`] over several encodings of the same rows (`shares[e]`, the rows
    /// in the same order under each): each resample draws one encoding, uniformly, and
    /// the units within each condition as [`Units::interval`] does, so the interval is
    /// where one encoding's accuracy may land. With one encoding, [`Units::interval`]
    /// itself.
    pub(super) fn interval_over_encodings(&self, shares: &[&[(usize, f64)]]) -> [f64; 2] {
        if let [one] = shares {
            return self.interval(one);
        }
        let totals: Vec<Vec<(f64, usize)>> = shares.iter().map(|s| self.totals(s)).collect();
        // The first bound's first index is the encoding; the rest of its indices go unused.
        let sizes = self.by_condition.iter().map(Vec::len);
        let bounds: Vec<usize> = std::iter::once(shares.len()).chain(sizes).collect();
        let rounds = self.resamples.max(1);
        let mut means: Vec<f64> = Vec::with_capacity(rounds);
        for_each_resample(self.seed, &bounds, rounds, |picked| {
            let (encoding, units) = picked.split_at(shares.len());
            means.push(self.resampled_mean(&totals[encoding[0]], units));
        });
        self.percentiles(means)
    }

    /// The mean over conditions of the row-weighted mean share of one resample's units
    /// (`picked`: each condition's draws in turn, indices into its units).
    fn resampled_mean(&self, totals: &[(f64, usize)], mut picked: &[usize]) -> f64 {
        mean(self.by_condition.iter().map(|units| {
            let here;
            (here, picked) = picked.split_at(units.len());
            let (mut s, mut n) = (0.0, 0usize);
            for &i in here {
                let u = units[i];
                s += totals[u].0;
                n += totals[u].1;
            }
            s / n.max(1) as f64
        }))
    }

    /// The 2.5th and 97.5th percentiles of the resampled `means`, or the Wilson score
    /// interval over the units where they are 0 or 1 alike.
    fn percentiles(&self, mut means: Vec<f64>) -> [f64; 2] {
        means.sort_by(f64::total_cmp);
        let (lower, upper) = (percentile(&means, 0.025), percentile(&means, 0.975));
        let units = self.by_condition.iter().map(Vec::len).sum();
        match wilson_at_the_bounds(lower, upper, units) {
            Some(w) => [w.lower, w.upper],
            None => [lower, upper],
        }
    }

    /// Per unit, the mean share of `a` minus that of `b`.
    fn differences(&self, a: &[(usize, f64)], b: &[(usize, f64)]) -> Vec<f64> {
        let (ta, tb) = (self.totals(a), self.totals(b));
        ta.iter()
            .zip(&tb)
            .map(|(x, y)| (x.0 - y.0) / x.1.max(1) as f64)
            .collect()
    }

    /// The paired sign-flip test of `s` against `other` over units: its p-value and the
    /// accuracy difference (`s` minus `other`).
    ///
    /// # Errors
    /// The two were not scored on the same rows.
    fn paired(
        &self,
        (name, s): (String, &Scored),
        (other_name, other): (&str, &Scored),
        params: &CompareParams,
    ) -> Result<(f64, f64)> {
        if other
            .shares
            .iter()
            .map(|x| x.0)
            .ne(s.shares.iter().map(|x| x.0))
        {
            let second = other_name.to_string();
            return Err(ClassifyError::Unpaired {
                first: name,
                second,
            }
            .into());
        }
        let d = self.differences(&s.shares, &other.shares);
        let p_value = sign_flip_p(&d, params.resamples, params.cv.seed)?;
        Ok((p_value, s.accuracy - other.accuracy))
    }

    /// `c`'s ranking entry, tested against the paper's method and, for the spiking
    /// network, against its inputs' counts (`against`: their scores, when they ran).
    pub(super) fn rank(
        &self,
        c: &Candidate,
        s: &Scored,
        (paper, counts): (Option<&Scored>, Option<&Scored>),
        params: &CompareParams,
    ) -> Result<Ranked> {
        let versus_paper = match paper {
            Some(p) if !c.is_paper() => {
                Some(self.paired((c.name(), s), ("the paper's method", p), params)?)
            }
            _ => None,
        };
        let versus_counts = match counts {
            Some(r) => Some(self.paired((c.name(), s), ("its inputs' rates", r), params)?),
            None => None,
        };
        Ok(Ranked {
            encoding: c.encoding.clone(),
            method: c.method.clone(),
            classifier: c.classifier.clone(),
            accuracy: s.accuracy,
            ci: self.interval(&s.shares),
            p_vs_paper: versus_paper.map(|a| a.0),
            difference_vs_paper: versus_paper.map(|a| a.1),
            difference_vs_rates: versus_counts.map(|a| a.1),
            p_vs_rates: versus_counts.map(|a| a.0),
            per_condition: s.per_condition.clone(),
            seconds: s.seconds,
            paper: c.is_paper(),
            over_encodings: None,
        })
    }
}

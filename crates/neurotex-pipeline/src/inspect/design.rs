//! The design of a dataset: recordings per class and condition, the groups its manifest
//! names, and which analyses its size supports with the folds and neighbours asked for.

use serde::Serialize;

use crate::recording::Meta;
use crate::values::Speed;

/// Recordings per class at one speed (or over all recordings).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Condition {
    /// The speed, mm/s; `None` for all recordings together.
    pub speed_mm_s: Option<f64>,
    /// Recordings of each class, in the order of [`Design::classes`].
    pub counts: Vec<usize>,
    /// The share of the largest class: what always naming it scores.
    pub chance: f64,
}

impl Condition {
    fn of(speed_mm_s: Option<f64>, classes: &[String], labels: &[&str]) -> Self {
        let counts: Vec<usize> = classes
            .iter()
            .map(|c| labels.iter().filter(|l| **l == c).count())
            .collect();
        let n: usize = counts.iter().sum();
        let largest = counts.iter().copied().max().unwrap_or(0);
        Condition {
            speed_mm_s,
            chance: largest as f64 / n.max(1) as f64,
            counts,
        }
    }

    /// The smallest class present at this condition, with its count (classes absent here
    /// are not counted).
    pub fn smallest(&self, classes: &[String]) -> Option<(String, usize)> {
        let present = self.counts.iter().enumerate().filter(|(_, &n)| n > 0);
        let (k, &n) = present.min_by_key(|(_, &n)| n)?;
        Some((classes[k].clone(), n))
    }

    /// The largest class count over the smallest present.
    pub fn imbalance(&self) -> f64 {
        let present: Vec<usize> = self.counts.iter().copied().filter(|&n| n > 0).collect();
        let (lo, hi) = (present.iter().min(), present.iter().max());
        match (lo, hi) {
            (Some(&lo), Some(&hi)) => hi as f64 / lo as f64,
            _ => 1.0,
        }
    }
}

/// A manifest column that groups recordings (trial, force, any further column).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GroupColumn {
    /// The column.
    pub column: String,
    /// Its distinct values.
    pub values: usize,
}

/// Whether the design supports one analysis.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Support {
    /// The analysis.
    pub analysis: String,
    /// Whether it can run as asked.
    pub supported: bool,
    /// Why, in numbers.
    pub why: String,
    /// The most folds (or, for KNN, neighbours) the design supports.
    pub limit: usize,
}

/// The design.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Design {
    /// The classes, sorted.
    pub classes: Vec<String>,
    /// All recordings together, then one per speed (when the manifest has speeds).
    pub conditions: Vec<Condition>,
    /// Columns that group recordings, with their distinct values.
    pub groups: Vec<GroupColumn>,
    /// The analyses and whether the design supports them.
    pub support: Vec<Support>,
}

impl Design {
    /// All recordings together.
    pub fn overall(&self) -> &Condition {
        &self.conditions[0]
    }

    /// The conditions of each speed.
    pub fn speeds(&self) -> &[Condition] {
        &self.conditions[1..]
    }
}

/// The design of the recordings `metas` under `folds` and `k` neighbours.
pub fn design(metas: &[Meta], folds: usize, k: usize) -> Design {
    let labels: Vec<&str> = metas.iter().map(|m| m.label.as_str()).collect();
    let mut classes: Vec<String> = labels.iter().map(|l| l.to_string()).collect();
    classes.sort();
    classes.dedup();
    let mut conditions = vec![Condition::of(None, &classes, &labels)];
    let speeds = Speed::distinct(metas.iter().filter_map(Meta::speed));
    for &speed in &speeds {
        let at: Vec<&str> = metas
            .iter()
            .filter(|m| m.speed() == Some(speed))
            .map(|m| m.label.as_str())
            .collect();
        conditions.push(Condition::of(Some(speed.mm_s()), &classes, &at));
    }
    let groups = group_columns(metas);
    let support = support(&classes, &conditions, metas, folds, k);
    Design {
        classes,
        conditions,
        groups,
        support,
    }
}

fn group_columns(metas: &[Meta]) -> Vec<GroupColumn> {
    let mut columns: Vec<String> = vec!["trial".into(), "force_n".into()];
    let extra = metas.iter().flat_map(|m| m.extra.keys());
    for c in extra {
        if !columns.contains(c) {
            columns.push(c.clone());
        }
    }
    columns
        .into_iter()
        .filter_map(|column| {
            let mut values: Vec<String> = metas.iter().filter_map(|m| m.field(&column)).collect();
            values.sort();
            values.dedup();
            values.retain(|v| !v.is_empty());
            (!values.is_empty()).then_some(GroupColumn {
                column,
                values: values.len(),
            })
        })
        .collect()
}

/// A class's fewest recordings in a training fold when `n` are dealt into `folds`.
fn in_training(n: usize, folds: usize) -> usize {
    n - n.div_ceil(folds.max(1))
}

fn support(
    classes: &[String],
    conditions: &[Condition],
    metas: &[Meta],
    folds: usize,
    k: usize,
) -> Vec<Support> {
    let mut out = Vec::new();
    let all = &conditions[0];
    let two = classes.len() >= 2;
    let (small, n_small) = all.smallest(classes).unwrap_or_default();
    out.push(Support {
        analysis: format!("evaluate: {folds}-fold cross-validation over all recordings"),
        supported: two && n_small >= folds,
        why: match two {
            false => format!("{} class(es): a classifier needs at least 2", classes.len()),
            true => format!(
                "each class needs {folds} recordings; the smallest, `{small}`, has {n_small}"
            ),
        },
        limit: n_small,
    });
    let speeds = &conditions[1..];
    let unspeeded = metas.iter().filter(|m| m.speed().is_none()).count();
    let within = speeds
        .iter()
        .filter_map(|c| Some((c.speed_mm_s?, c.smallest(classes)?)))
        .min_by_key(|(_, (_, n))| *n);
    out.push(Support {
        analysis: format!("reproduce: {folds}-fold cross-validation within each speed (E1-E5, E5c, E8, E9)"),
        supported: unspeeded == 0 && within.as_ref().is_some_and(|(_, (_, n))| *n >= folds) && two,
        why: match (&within, unspeeded) {
            (_, u) if u > 0 => format!("{u} recording(s) have no speed_mm_s"),
            (None, _) => "no speeds".to_string(),
            (Some((speed, (label, n))), _) => format!("each class needs {folds} recordings at each speed; `{label}` has {n} at {speed} mm/s"),
        },
        limit: within.as_ref().map_or(0, |(_, (_, n))| *n),
    });
    out.push(Support {
        analysis: "reproduce: trained on the other speeds, tested on one (E6)".to_string(),
        supported: speeds.len() >= 2 && unspeeded == 0,
        why: format!("needs at least 2 speeds; the manifest has {}", speeds.len()),
        limit: speeds.len(),
    });
    let fewest = speeds
        .iter()
        .flat_map(|c| c.counts.iter().filter(|&&n| n > 0))
        .map(|&n| in_training(n, folds))
        .min()
        .unwrap_or_else(|| in_training(n_small, folds));
    out.push(Support {
        analysis: format!("KNN with k = {k} neighbours, within each speed"),
        supported: k <= fewest,
        why: format!("a class has as few as {fewest} recording(s) in a training fold; more than {fewest} neighbours can tie or outvote it whatever the features say"),
        limit: fewest,
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn meta(label: &str, speed: f64, trial: i64) -> Meta {
        Meta {
            label: label.into(),
            speed_mm_s: Some(speed),
            trial: Some(trial),
            ..Meta::default()
        }
    }

    #[test]
    fn a_hand_counted_design() {
        // A: 3 at 5 mm/s, 3 at 10; B: 1 at 5, 3 at 10
        let mut metas = Vec::new();
        for t in 0..3 {
            metas.push(meta("A", 5.0, t));
            metas.push(meta("A", 10.0, t));
            metas.push(meta("B", 10.0, t));
        }
        metas.push(meta("B", 5.0, 0));
        let d = design(&metas, 3, 2);
        assert_eq!(d.classes, ["A", "B"]);
        assert_eq!(d.overall().counts, [6, 4]);
        assert_eq!(d.overall().chance, 0.6);
        assert_eq!(d.speeds()[0].counts, [3, 1]);
        assert_eq!(d.speeds()[0].chance, 0.75);
        assert_eq!(d.speeds()[0].imbalance(), 3.0);
        assert_eq!(
            d.groups[0],
            GroupColumn {
                column: "trial".into(),
                values: 3
            }
        );
        let s = &d.support;
        assert!(s[0].supported, "{}", s[0].why);
        assert!(!s[1].supported && s[1].why.contains("`B` has 1 at 5 mm/s"));
        assert!(s[2].supported);
        // B's single recording at 5 mm/s leaves it none in some training fold
        assert!(!s[3].supported && s[3].why.contains("as few as 0"));
    }
}

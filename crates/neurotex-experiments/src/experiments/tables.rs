//! The feature tables every analysis reads, built once, and the headline evaluations (the
//! paper's two approaches and 2D-GLCM at each speed, on every encoding) that several
//! analyses compare against.

use super::{Prepared, ValidReproduceParams};
use crate::analysis::{evaluate, evaluate_sweep, Columns, FeatureTable, Outcome, Split};
use crate::classify::{Knn, Sweep, ValidCv};
use crate::error::Result;
use crate::pipeline::{Encoded, Method};
use crate::values::{BySpeed, Speed};

/// The paper's two approaches, and 2D-GLCM (E4), evaluated by cross-validation at one
/// speed.
#[derive(Debug, Clone, PartialEq)]
pub struct Headline {
    /// Single taxel, every taxel in turn (mean, per taxel, best).
    pub taxel: Outcome,
    /// 3D-GLCM.
    pub glcm3d: Outcome,
    /// 2D-GLCM.
    pub glcm2d: Outcome,
}

/// Feature tables over all recordings, and the headline evaluations per speed.
#[derive(Debug, Clone)]
pub struct Tables {
    /// Single-taxel statistics of every taxel.
    pub taxel: FeatureTable,
    /// 3D-GLCM features.
    pub glcm3d: FeatureTable,
    /// 2D-GLCM features.
    pub glcm2d: FeatureTable,
    /// Both approaches by cross-validation at each speed; empty when that cannot run
    /// (`within_speed` says why).
    pub headline: BySpeed<Headline>,
    /// Why the cross-validation within each speed cannot run with the folds and neighbours
    /// asked for; the analyses resting on it are skipped with this reason.
    pub within_speed: Option<String>,
    /// The headline evaluations of each further encoding ([`Prepared::perturbed`]), on the
    /// same folds.
    pub perturbed: Vec<BySpeed<Headline>>,
    /// The single-taxel and 3D-GLCM tables of each further encoding, in the order of
    /// `perturbed` (the analyses beyond the headline that run over encodings read them).
    pub perturbed_tables: Vec<EncodingTables>,
}

/// The single-taxel and 3D-GLCM feature tables of one further encoding.
#[derive(Debug, Clone)]
pub struct EncodingTables {
    /// Single-taxel statistics of every taxel.
    pub taxel: FeatureTable,
    /// 3D-GLCM features.
    pub glcm3d: FeatureTable,
}

impl Tables {
    /// Builds the three tables and the headline evaluations, of the recordings as run and
    /// of each further encoding.
    ///
    /// # Errors
    /// A recording too short for one bin, or a classification that cannot run.
    pub fn build(prepared: &Prepared, params: &ValidReproduceParams) -> Result<Self> {
        let encoded = &prepared.encoded;
        let taxel = table(encoded, Method::Taxel, params)?;
        let glcm3d = table(encoded, Method::Glcm3d, params)?;
        let glcm2d = table(encoded, Method::Glcm2d, params)?;
        let (headline, within_speed) = match &prepared.within_speed {
            Some(why) => (BySpeed::new(), Some(why.clone())),
            None => {
                match evaluate_headline(&[&taxel, &glcm3d, &glcm2d], &prepared.speeds, params) {
                    Ok(h) => (h, None),
                    // Folds made by groups are checked only here.
                    Err(e) if e.is_design() => (BySpeed::new(), Some(e.to_string())),
                    Err(e) => return Err(e),
                }
            }
        };
        // The further encodings are evaluated where the encoding as run was.
        let speeds: &[Speed] = match within_speed {
            Some(_) => &[],
            None => &prepared.speeds,
        };
        let (perturbed, perturbed_tables) = prepared
            .perturbed
            .iter()
            .map(|encoded| {
                let tables = [Method::Taxel, Method::Glcm3d, Method::Glcm2d]
                    .map(|m| table(encoded, m, params));
                let [t, g3, g2] = tables;
                let (taxel, glcm3d) = (t?, g3?);
                let h = evaluate_headline(&[&taxel, &glcm3d, &g2?], speeds, params)?;
                Ok((h, EncodingTables { taxel, glcm3d }))
            })
            .collect::<Result<Vec<_>>>()?
            .into_iter()
            .unzip();
        Ok(Tables {
            taxel,
            glcm3d,
            glcm2d,
            headline,
            within_speed,
            perturbed,
            perturbed_tables,
        })
    }

    /// The single-taxel and 3D-GLCM tables of every encoding: as run, then each further one.
    pub fn encoding_tables(&self) -> Vec<(&FeatureTable, &FeatureTable)> {
        std::iter::once((&self.taxel, &self.glcm3d))
            .chain(self.perturbed_tables.iter().map(|e| (&e.taxel, &e.glcm3d)))
            .collect()
    }

    /// The headline evaluations at `speed` of every encoding: as run, then each further one.
    pub fn encodings_at(&self, speed: Speed) -> Vec<&Headline> {
        std::iter::once(self.at(speed))
            .chain(self.perturbed.iter().filter_map(|p| p.get(speed)))
            .collect()
    }

    /// The headline evaluations at `speed`, a speed of the prepared data.
    ///
    /// # Panics
    /// If `speed` is not one of the prepared speeds, or the cross-validation within each
    /// speed could not run (a caller bug: such analyses are skipped before they run).
    pub fn at(&self, speed: Speed) -> &Headline {
        self.headline
            .get(speed)
            .expect("headline evaluations exist at every prepared speed")
    }
}

/// The headline evaluations of the tables `[taxel, glcm3d, glcm2d]` at each speed.
fn evaluate_headline(
    [taxel, glcm3d, glcm2d]: &[&FeatureTable; 3],
    speeds: &[Speed],
    params: &ValidReproduceParams,
) -> Result<BySpeed<Headline>> {
    let (knn, folds) = (params.knn(), params.folds());
    speeds
        .iter()
        .map(|&s| {
            let at = |e: crate::Error| {
                e.in_analysis(format!("at {s} mm/s, the cross-validation within a speed"))
            };
            let h = Headline {
                taxel: cv_at(taxel, Columns::EachTaxel, s, knn, folds).map_err(at)?,
                glcm3d: cv_at(glcm3d, Columns::All, s, knn, folds).map_err(at)?,
                glcm2d: cv_at(glcm2d, Columns::All, s, knn, folds).map_err(at)?,
            };
            Ok((s, h))
        })
        .collect()
}

/// `method`'s features of `encoded` (recordings of one grid).
///
/// # Errors
/// A recording too short for one bin.
pub fn table(
    encoded: &[Encoded],
    method: Method,
    params: &ValidReproduceParams,
) -> Result<FeatureTable> {
    let extractor = params.pipeline().extractor(&encoded[0].spikes.grid())?;
    FeatureTable::build(encoded, &extractor, method)
}

/// Cross-validation of `table`'s `columns` over the recordings at `speed`, folds keeping
/// each group of manifest column `group_by` together when given.
///
/// # Errors
/// A classification that cannot run, or a missing group column.
pub fn cv_at(
    table: &FeatureTable,
    columns: Columns,
    speed: Speed,
    knn: &Knn,
    folds: (ValidCv, Option<&str>),
) -> Result<Outcome> {
    evaluate(table, columns, &cv_split(speed, folds), knn)
}

/// [`cv_at`] of every setting of `sweep`, one outcome each.
///
/// # Errors
/// As [`cv_at`].
pub fn cv_sweep_at<C: Sweep>(
    table: &FeatureTable,
    columns: Columns,
    speed: Speed,
    sweep: &C,
    folds: (ValidCv, Option<&str>),
) -> Result<Vec<Outcome>> {
    evaluate_sweep(table, columns, &cv_split(speed, folds), sweep)
}

/// Cross-validation over the recordings at `speed`.
fn cv_split(speed: Speed, (cv, group_by): (ValidCv, Option<&str>)) -> Split {
    Split::CrossValidation {
        speeds: Some(vec![speed]),
        cv,
        group_by: group_by.map(str::to_string),
    }
}

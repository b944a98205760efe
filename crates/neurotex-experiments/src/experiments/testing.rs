//! A small prepared run shared by the analyses' unit tests: the golden test's design (4
//! textures x 10, 20 mm/s x 6 trials of short slides), prepared once per test binary.

use std::sync::OnceLock;

use super::{prepare, Context, Prepared, ReproduceParams, Source, Tables, ValidReproduceParams};
use crate::classify::CvParams;
use crate::sim::{design, RigParams, Texture};

/// Prepared recordings, tables and parameters of the small design.
pub struct SmallRun {
    pub prepared: Prepared,
    pub tables: Tables,
    pub params: ValidReproduceParams,
}

impl SmallRun {
    pub fn context(&self) -> Context<'_> {
        Context {
            prepared: &self.prepared,
            tables: &self.tables,
            params: &self.params,
        }
    }
}

pub fn small_run() -> &'static SmallRun {
    static RUN: OnceLock<SmallRun> = OnceLock::new();
    RUN.get_or_init(|| {
        let rig = RigParams {
            hold_s: 0.5,
            slide_mm: 20.0,
            ..RigParams::default()
        };
        let textures = [Texture::Ft1, Texture::Sb, Texture::Stf, Texture::Cp];
        let source = Source::Simulated {
            rig: Box::new(rig),
            trials: design(&textures, &[10.0, 20.0], 6),
            seed: 7,
        };
        let params = ReproduceParams {
            cv: CvParams {
                folds: 3,
                seed: 0,
                repeats: 2,
            },
            e3_repeats: 2,
            e3_counts: vec![4, 16],
            e5_fractions: vec![0.5, 1.0],
            e7_gains: vec![5.0, 8.0],
            e8_ks: vec![1, 5],
            encoder_draws: 3,
            ..ReproduceParams::default()
        }
        .check()
        .expect("valid parameters");
        let prepared = prepare(&source, &params, &|_| {}).expect("prepared");
        let tables = Tables::build(&prepared, &params).expect("tables");
        SmallRun {
            prepared,
            tables,
            params,
        }
    })
}

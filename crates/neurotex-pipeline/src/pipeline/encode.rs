//! The planned pipeline: a recording conditioned and encoded into spike trains, alone or a
//! dataset's in parallel, and recorded events read as spike trains.

use std::path::Path;

use rayon::prelude::*;

use super::{Encoded, Encoding, FeatureExtractor, PipelineParams};
use crate::encode::{encode, encode_drives, encode_fa, encode_sa_fa, Drive, SpikeTrains};
use crate::error::{DataError, ParamError, Result};
use crate::events::Events;
use crate::recording::{Baseline, Dataset, Meta, Recording};
use crate::signal::{Conditioned, Preprocessor};
use crate::values::Grid;

/// The planned pipeline.
#[derive(Debug, Clone)]
pub struct Pipeline {
    params: PipelineParams,
    preprocessor: Preprocessor,
}

impl Pipeline {
    /// Checks the parameters and plans the stages.
    ///
    /// # Errors
    /// A broken parameter rule.
    pub fn new(params: PipelineParams) -> Result<Self, ParamError> {
        params.check()?;
        let preprocessor = Preprocessor::new(&params.preprocess)?;
        Ok(Pipeline {
            params,
            preprocessor,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &PipelineParams {
        &self.params
    }

    /// Conditions one recording (sliding phase, 1 kHz, baseline, low-pass, normalised),
    /// checking it lasts at least one bin.
    ///
    /// # Errors
    /// An empty sliding phase or a selected phase shorter than one bin.
    pub fn condition(&self, rec: &Recording, dataset_baseline: Baseline) -> Result<Conditioned> {
        let cond = self.preprocessor.apply(rec, dataset_baseline)?;
        let bin = self.params.volume.bin_ms;
        if cond.n_steps() < bin {
            return Err(DataError::invalid(
                &rec.meta.file,
                format!(
                    "the selected phase lasts {} ms, shorter than one {bin} ms bin",
                    cond.n_steps()
                ),
            )
            .into());
        }
        Ok(cond)
    }

    /// Encodes a conditioned recording with the pipeline's SA neurons.
    ///
    /// # Errors
    /// A broken encoder rule.
    pub fn encode_conditioned(&self, rec: &Recording, cond: &Conditioned) -> Result<SpikeTrains> {
        let l = &rec.layout;
        let params = self.params.encoder;
        Ok(encode(&cond.samples, l.rows, l.cols, &l.present, params)?)
    }

    /// Encodes a conditioned recording with the populations of the pipeline's encoding:
    /// `(first population, FA population of sa+fa)`, as [`Encoded::spikes`] and
    /// [`Encoded::fa`].
    ///
    /// # Errors
    /// A broken encoder rule.
    pub fn encode_populations(
        &self,
        rec: &Recording,
        cond: &Conditioned,
    ) -> Result<(SpikeTrains, Option<SpikeTrains>)> {
        let l = &rec.layout;
        let fa = || {
            encode_fa(
                &cond.samples,
                l.rows,
                l.cols,
                &l.present,
                self.params.encoder,
                self.params.fa,
            )
        };
        Ok(match self.params.encoding {
            Encoding::Sa => (self.encode_conditioned(rec, cond)?, None),
            Encoding::Fa => (fa()?, None),
            Encoding::SaFa => {
                let (sa, fa) = self.encode_sa_fa(rec, cond)?;
                (sa, Some(fa))
            }
        })
    }

    /// Encodes several inputs of one recording (conditioned signals of its grid and of one
    /// length, such as the perturbed draws of the encoder's sensitivity) with the
    /// populations of the pipeline's encoding, all in one call: the same trains, bit for
    /// bit, as [`Pipeline::encode_populations`] of each input alone, in the order of
    /// `inputs`.
    ///
    /// Each population of each input is a bank of neurons of its own, and the banks run
    /// side by side ([`encode_drives`]): a neuron's state depends on its own input only, so
    /// the vector lanes hold several inputs' neurons at once without changing a bit.
    ///
    /// # Errors
    /// A broken encoder rule.
    ///
    /// # Panics
    /// If the inputs differ in length (a caller bug).
    pub fn encode_populations_side_by_side(
        &self,
        rec: &Recording,
        inputs: &[&[f64]],
    ) -> Result<Vec<(SpikeTrains, Option<SpikeTrains>)>> {
        let (l, p) = (&rec.layout, &self.params);
        let encoding = p.encoding;
        if encoding != Encoding::Sa {
            p.fa.check()?;
        }
        let mut drives = Vec::new();
        let mut gains = Vec::new();
        for &input in inputs {
            if encoding != Encoding::Fa {
                drives.push(Drive::Signal(input));
                gains.push(p.encoder.gain);
            }
            if encoding != Encoding::Sa {
                drives.push(Drive::RectifiedRate(input));
                gains.push(p.fa.gain);
            }
        }
        // FA alone runs the SA firing type at the FA gain, as `encode_fa` does.
        let neuron = match encoding {
            Encoding::Fa => p.encoder.with_gain(p.fa.gain),
            Encoding::Sa | Encoding::SaFa => p.encoder,
        };
        let trains = encode_drives(&mut drives, &gains, l.rows, l.cols, &l.present, neuron)?;
        let mut trains = trains.into_iter();
        let mut next = || trains.next().expect("one bank per population and input");
        Ok(inputs
            .iter()
            .map(|_| match encoding {
                Encoding::Sa | Encoding::Fa => (next(), None),
                Encoding::SaFa => (next(), Some(next())),
            })
            .collect())
    }

    /// Encodes a conditioned recording with the pipeline's SA neurons and its FA
    /// population side by side ([`encode_sa_fa`]), whatever the pipeline's encoding.
    ///
    /// # Errors
    /// A broken encoder rule.
    pub fn encode_sa_fa(
        &self,
        rec: &Recording,
        cond: &Conditioned,
    ) -> Result<(SpikeTrains, SpikeTrains)> {
        let (l, p) = (&rec.layout, &self.params);
        Ok(encode_sa_fa(
            &cond.samples,
            l.rows,
            l.cols,
            &l.present,
            p.encoder,
            p.fa,
        )?)
    }

    /// Conditions and encodes one recording.
    ///
    /// # Errors
    /// An empty sliding phase or a selected phase shorter than one bin.
    pub fn encode(&self, rec: &Recording, dataset_baseline: Baseline) -> Result<Encoded> {
        let cond = self.condition(rec, dataset_baseline)?;
        self.encode_recording(rec, &cond)
    }

    /// Encodes a conditioned recording with the populations of the pipeline's encoding.
    ///
    /// # Errors
    /// A broken encoder rule.
    fn encode_recording(&self, rec: &Recording, cond: &Conditioned) -> Result<Encoded> {
        let populations = self.encode_populations(rec, cond)?;
        Ok(Encoded::of(rec, cond, populations))
    }

    /// Loads and encodes the dataset's recordings `indices` in parallel, calling
    /// `on_done` once per finished recording (for a progress bar). The output keeps the
    /// order of `indices`; a dataset's raw samples are never all in memory at once.
    ///
    /// # Errors
    /// The first failing recording's error.
    pub fn encode_dataset(
        &self,
        dataset: &Dataset,
        indices: &[usize],
        on_done: &(dyn Fn() + Sync),
    ) -> Result<Vec<Encoded>> {
        if dataset.is_events() {
            return indices
                .par_iter()
                .map(|&i| {
                    crate::progress::stop_point();
                    let events = dataset.load_events(i)?;
                    let path = dataset.root.join(&dataset.entries[i].file);
                    let encoded = self.from_events(dataset.entries[i].clone(), events, &path)?;
                    on_done();
                    Ok(encoded)
                })
                .collect();
        }
        let pairs = self.encode_dataset_with(dataset, indices, on_done, &|_, _| Ok(()))?;
        Ok(pairs.into_iter().map(|(e, ())| e).collect())
    }

    /// An address-event recording as the pipeline's encoding reads it: its ON trains in
    /// the SA population's place and its OFF trains in the FA population's (`sa` reads ON,
    /// `fa` OFF, `sa+fa` both). The encoder does not run.
    ///
    /// # Errors
    /// `fa` or `sa+fa` on a recording without polarities.
    pub fn from_events(&self, meta: Meta, events: Events, path: &Path) -> Result<Encoded> {
        events_encoded(self.params.encoding, meta, events, path)
    }
    /// [`Pipeline::encode_dataset`], also applying `also` to each recording and its
    /// conditioned signal while both are in memory (the baselines without spikes read
    /// the signal the encoder receives without conditioning it twice).
    ///
    /// # Errors
    /// The first failing recording's error, from the encoding or from `also`.
    pub fn encode_dataset_with<T: Send>(
        &self,
        dataset: &Dataset,
        indices: &[usize],
        on_done: &(dyn Fn() + Sync),
        also: &(dyn Fn(&Recording, &Conditioned) -> Result<T> + Sync),
    ) -> Result<Vec<(Encoded, T)>> {
        let baseline = dataset.layout.baseline.unwrap_or_default();
        indices
            .par_iter()
            .map(|&i| {
                crate::progress::stop_point();
                let rec = dataset.load(i)?;
                let cond = self.condition(&rec, baseline)?;
                let encoded = self.encode_recording(&rec, &cond)?;
                let extra = also(&rec, &cond)?;
                on_done();
                Ok((encoded, extra))
            })
            .collect()
    }

    /// A feature extractor for trains of this grid.
    ///
    /// # Errors
    /// A broken parameter rule.
    pub fn extractor(&self, grid: &Grid) -> Result<FeatureExtractor, ParamError> {
        FeatureExtractor::new(&self.params, grid)
    }
}

/// [`Pipeline::from_events`] for `encoding`.
///
/// # Errors
/// `fa` or `sa+fa` on a recording without polarities.
pub fn events_encoded(
    encoding: Encoding,
    meta: Meta,
    events: Events,
    path: &Path,
) -> Result<Encoded> {
    let trains = |lists: &[Vec<u32>]| {
        SpikeTrains::from_lists(
            lists,
            events.rows,
            events.cols,
            &events.present,
            events.n_steps,
        )
    };
    let off = || {
        events.off.as_deref().map(trains).ok_or_else(|| {
                let why = format!(
                    "has no polarity column, so no OFF events: the `{}` encoding reads OFF events as its FA population; use --encoding sa (ON events)",
                    encoding.name()
                );
                crate::Error::from(DataError::invalid(path, why))
            })
    };
    let (spikes, fa) = match encoding {
        Encoding::Sa => (trains(&events.on), None),
        Encoding::Fa => (off()?, None),
        Encoding::SaFa => (trains(&events.on), Some(off()?)),
    };
    Ok(Encoded {
        meta,
        spikes,
        fa,
        resampled: false,
        flat: false,
        constant: false,
        from_events: true,
    })
}

impl Encoded {
    /// The encoder's populations `(first, fa)` of `rec`, conditioned as `cond`.
    pub fn of(
        rec: &Recording,
        cond: &Conditioned,
        (spikes, fa): (SpikeTrains, Option<SpikeTrains>),
    ) -> Encoded {
        Encoded {
            meta: rec.meta.clone(),
            spikes,
            fa,
            resampled: cond.resampled,
            flat: cond.flat,
            constant: rec.is_constant(),
            from_events: false,
        }
    }
}

//! A stream's steps: each frame checked and followed in time, resampled onto the 1 ms grid,
//! conditioned, encoded, and at each bin boundary the window classified; an episode ended
//! with its summary.

use crate::causal::{network_window, BinDecision, Decider, EpisodeEnd, EpisodeSummary};
use crate::encode::{Encoder, SpikeTrains};
use crate::error::Result;
use crate::model::{Model, Prediction};
use crate::network::NetworkFeed;
use crate::pipeline::{Encoded, Encoding};
use crate::recording::Meta;
use crate::saved::SavedModel;
use crate::signal::{Butterworth2, RestTracker, ENCODER_FS};
use crate::spike_log::SpikeLog;
use crate::spiking_model::decide;

use super::params::MAX_STAMP_S;
use super::{BadFrame, EpisodeState, Event, Kept, StreamClassifier, StreamError};

impl StreamClassifier {
    pub(super) fn check_frame(&self, time_s: Option<f64>, values: &[f64]) -> Result<(), BadFrame> {
        let expected = self.channel_cells.len();
        if values.len() != expected {
            return Err(BadFrame::FieldCount {
                expected,
                got: values.len(),
            });
        }
        let first_value = usize::from(time_s.is_some());
        if let Some(t) = time_s {
            if !t.is_finite() {
                return Err(BadFrame::StampNotFinite { t });
            }
            if t.abs() > MAX_STAMP_S {
                return Err(BadFrame::StampRange { t });
            }
        }
        // One pass without early exit (it vectorises); the position only for a bad frame.
        let in_range = crate::values::sample_in_range;
        if values.iter().fold(false, |bad, &v| bad | !in_range(v)) {
            let i = values.iter().position(|&v| !in_range(v)).unwrap_or(0);
            let index = i + first_value;
            return Err(match values[i].is_finite() {
                false => BadFrame::NotFinite {
                    index,
                    value: values[i],
                },
                true => BadFrame::OutOfRange {
                    index,
                    value: values[i],
                },
            });
        }
        Ok(())
    }

    /// Whether a frame stamped `t` (otherwise good) moves the stream's clock: `Ok(false)`
    /// when it follows the previous frame, `Ok(true)` when it follows the last frame refused
    /// instead (the clock jumped there), the bad frame otherwise. Only frames that reach
    /// this check touch the clock, so a frame refused for its values cannot confirm a jump.
    pub(super) fn follow(&mut self, t: f64) -> Result<bool, BadFrame> {
        let max_gap_s = self.params.max_gap_s;
        // Events may share a stamp; frames may not.
        let equal = self.event_input.is_some();
        let follows = |p: f64| (t > p || (equal && t == p)) && t - p <= max_gap_s;
        let stray = self.stray_stamp.take();
        let Some(previous) = self.previous_stamp else {
            self.previous_stamp = Some(t);
            return Ok(false);
        };
        // When it follows both (a repeated stamp was refused), the clock has not moved.
        if follows(previous) || stray.is_some_and(follows) {
            self.previous_stamp = Some(t);
            return Ok(!follows(previous));
        }
        self.stray_stamp = Some(t);
        Err(match t <= previous {
            true if equal => BadFrame::Order { t, previous },
            true => BadFrame::Stamp { t, previous },
            false => BadFrame::Jump {
                t,
                previous,
                max_gap_s,
            },
        })
    }

    /// The largest taxel value of the current frame, resting value removed, in units of
    /// the scale (unfiltered): what onset episodes compare to their level.
    pub(super) fn contact_level(&self) -> f64 {
        let c = &self.conditioning;
        self.channel_cells
            .iter()
            .map(|&cell| (self.cell_frame[cell] - c.offsets[cell]) / c.scale)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    pub(super) fn new_episode(&self, origin: f64) -> EpisodeState {
        let cells = self.rows * self.cols;
        let p = self.model.params();
        let neuron = |gain: f64| {
            Encoder::new(p.encoder.with_gain(gain), cells).expect("the model's checked parameters")
        };
        let neurons = match p.encoding {
            Encoding::Sa => vec![(neuron(p.encoder.gain), false)],
            Encoding::Fa => vec![(neuron(p.fa.gain), true)],
            Encoding::SaFa => vec![(neuron(p.encoder.gain), false), (neuron(p.fa.gain), true)],
        };
        let (spikes, network) = match &self.model {
            SavedModel::Features(_) => (vec![SpikeLog::default(); neurons.len()], None),
            SavedModel::Spiking(m) => {
                let net = m.network();
                let window = network_window(self.window, self.bin, net.dt_ms as usize);
                (
                    Vec::new(),
                    Some(NetworkFeed::new(net, &self.present, window)),
                )
            }
        };
        EpisodeState {
            origin,
            frames: 0,
            before_t: 0.0,
            last_t: 0.0,
            next: 0,
            steps: 0,
            filter_state: [vec![0.0; cells], vec![0.0; cells]],
            has_previous: false,
            kept: Kept {
                spikes,
                network,
                glcm: match &self.empty_glcm {
                    Some(empty) => vec![empty.clone(); neurons.len()],
                    None => Vec::new(),
                },
            },
            neurons,
            decider: Decider::new(self.params.rule),
            bins: 0,
            rest_since: None,
            tracker: (p.preprocess.drift_window_ms)
                .map(|w| RestTracker::new(cells, w).expect("a window checked with the model")),
        }
    }

    /// Takes the current frame, at `t` s from the episode's start, into the resampler
    /// and conditions each 1 kHz step before `t`: those steps lie between the last frame
    /// and this one, as [`crate::signal::resample_linear`] brackets them.
    pub(super) fn resample(&mut self, t: f64) -> Result<(), StreamError> {
        let episode = self.episode.as_mut().expect("an episode is under way");
        if episode.frames > 0 {
            let ta = episode.last_t;
            loop {
                let episode = self.episode.as_mut().expect("an episode is under way");
                let ts = 0.0 + episode.next as f64 / ENCODER_FS;
                if ts >= t {
                    break;
                }
                episode.next += 1;
                let w = ((ts - ta) / (t - ta)).clamp(0.0, 1.0);
                interpolate(&self.last, &self.cell_frame, w, &mut self.step_in);
                self.step()?;
            }
        }
        let episode = self.episode.as_mut().expect("an episode is under way");
        std::mem::swap(&mut self.before, &mut self.last);
        self.last.copy_from_slice(&self.cell_frame);
        episode.before_t = episode.last_t;
        episode.last_t = t;
        episode.frames += 1;
        Ok(())
    }

    /// The episode's last steps, up to its last frame's time, as offline: bracketed by
    /// the last two frames (clamped beyond the last), or the only frame.
    pub(super) fn flush(&mut self) -> Result<(), StreamError> {
        if self.event_input.is_some() {
            return self.flush_events();
        }
        let episode = self.episode.as_mut().expect("an episode is under way");
        let (ta, tb) = (episode.before_t, episode.last_t);
        let total = match episode.frames {
            0 => return Ok(()),
            1 => 1,
            _ => crate::signal::resampled_len(tb, ENCODER_FS, 1)
                .expect("a span bounded by the longest episode"),
        };
        loop {
            let episode = self.episode.as_mut().expect("an episode is under way");
            if episode.next >= total {
                return Ok(());
            }
            let ts = 0.0 + episode.next as f64 / ENCODER_FS;
            episode.next += 1;
            match episode.frames {
                1 => self.step_in.copy_from_slice(&self.last),
                _ => {
                    let w = ((ts - ta) / (tb - ta)).clamp(0.0, 1.0);
                    interpolate(&self.before, &self.last, w, &mut self.step_in);
                }
            }
            self.step()?;
        }
    }

    /// Conditions one 1 kHz step (`step_in`, raw values per cell), runs the neurons,
    /// keeps their spikes, and classifies at a bin boundary.
    ///
    /// The cells go through every stage [`PART`] at a time, so that a large skin's step
    /// reads and writes each cell's state once while the part's values stay in the
    /// cache. Conditioning removes the resting value, filters and scales, with the
    /// operations of the offline pipeline in its order. Masked cells are filtered too:
    /// their input is 0 and a filter started at 0 stays at exactly 0, as offline, where
    /// they are left out; including them keeps the loop free of gathers.
    pub(super) fn step(&mut self) -> Result<(), StreamError> {
        let episode = self.episode.as_mut().expect("an episode is under way");
        let first = episode.steps == 0;
        let cells = self.rows * self.cols;
        let has_fa = episode.neurons.iter().any(|n| n.1);
        let [z0, z1] = &mut episode.filter_state;
        let offsets = match &mut episode.tracker {
            Some(tracker) => {
                tracker.push(&self.step_in, &mut self.rest);
                &self.rest
            }
            None => &self.conditioning.offsets,
        };
        episode.kept.begin_step();
        for start in (0..cells).step_by(PART) {
            let part = start..(start + PART).min(cells);
            let conditioning = Conditioning {
                raw: &self.step_in[part.clone()],
                offsets: &offsets[part.clone()],
                present: &self.present[part.clone()],
                state: [&mut z0[part.clone()], &mut z1[part.clone()]],
                out: &mut self.conditioned[part.clone()],
            };
            conditioning.run(self.filter.as_ref(), self.conditioning.scale, first);
            let raster = &mut self.raster[part.clone()];
            for (population, (neurons, is_fa)) in episode.neurons.iter_mut().enumerate() {
                let input = match is_fa {
                    false => &self.conditioned[part.clone()],
                    true => {
                        let drive = &mut self.drive[part.clone()];
                        let x = &self.conditioned[part.clone()];
                        let p = &self.previous[part.clone()];
                        for ((d, &x), &p) in drive.iter_mut().zip(x).zip(p) {
                            *d = if episode.has_previous {
                                (x - p).abs()
                            } else {
                                0.0
                            };
                        }
                        &*drive
                    }
                };
                neurons.run_part(part.start, input, raster);
                let present = &self.present[part.clone()];
                episode.kept.add(population, part.start, raster, present);
            }
        }
        if has_fa {
            std::mem::swap(&mut self.previous, &mut self.conditioned);
            episode.has_previous = true;
        }
        self.end_step()
    }

    /// Ends the episode's current 1 ms step, whose spikes were added: the network's step
    /// when its time step is complete, and the window's classification at a bin boundary.
    pub(super) fn end_step(&mut self) -> Result<(), StreamError> {
        let episode = self.episode.as_mut().expect("an episode is under way");
        episode.steps += 1;
        if let (Some(feed), SavedModel::Spiking(m)) = (&mut episode.kept.network, &self.model) {
            feed.end_ms(m.network());
        }
        if episode.steps.is_multiple_of(self.bin) {
            for window in &mut episode.kept.glcm {
                window.close_bin();
            }
            self.boundary()?;
        }
        Ok(())
    }

    /// Classifies the window ending at the current step, a bin boundary.
    pub(super) fn boundary(&mut self) -> Result<(), StreamError> {
        let episode = self.episode.as_mut().expect("an episode is under way");
        let end = episode.steps;
        let start = end.saturating_sub(self.window);
        // Later windows start later, and the episode's summary no earlier than this one.
        for log in &mut episode.kept.spikes {
            log.drop_before(start);
        }
        let (class, shares) = match (&self.model, &episode.kept.network) {
            (SavedModel::Spiking(m), Some(feed)) => decide(&feed.scores(m.network())),
            (SavedModel::Features(m), _) => {
                let prediction = match episode.kept.glcm.is_empty() {
                    true => self.classify(m, start, end)?,
                    false => self.classify_window(m)?,
                };
                (m.class_index(&prediction.predicted), prediction.shares)
            }
            (SavedModel::Spiking(_), None) => unreachable!("a spiking model's episode runs it"),
        };
        let t_s = end as f64 / 1000.0;
        let episode = self.episode.as_mut().expect("an episode is under way");
        let decided = episode.decider.observe(t_s, class, shares[class]);
        episode.bins += 1;
        let decision = episode.decider.decision().map(|d| d.0);
        self.events.push(Event::Bin(BinDecision {
            t_s,
            class,
            shares,
            decided,
            decision,
        }));
        Ok(())
    }

    /// The model's prediction for the steps `[start, end)` of the episode.
    pub(super) fn classify(
        &self,
        model: &Model,
        start: usize,
        end: usize,
    ) -> Result<Prediction, StreamError> {
        let episode = self.episode.as_ref().expect("an episode is under way");
        let trains: Vec<SpikeTrains> = episode
            .kept
            .spikes
            .iter()
            .map(|log| log.trains(start, end, (self.rows, self.cols), &self.present))
            .collect();
        let mut populations = trains.into_iter();
        let encoded = Encoded {
            meta: Meta {
                file: "stream".into(),
                speed_mm_s: self.params.speed_mm_s,
                ..Meta::default()
            },
            spikes: populations.next().expect("one population at least"),
            fa: populations.next(),
            resampled: false,
            flat: false,
            constant: false,
            from_events: false,
        };
        Ok(model.predict_one(&encoded)?)
    }

    /// The model's prediction for the current window from its co-occurrence counts kept
    /// bin by bin (3D-GLCM models): the same features as [`StreamClassifier::classify`]
    /// gives at a bin boundary, without counting the window afresh.
    fn classify_window(&self, model: &Model) -> Result<Prediction, StreamError> {
        let episode = self.episode.as_ref().expect("an episode is under way");
        let extractor = model.extractor();
        let volume = extractor.volume_params();
        let symmetric = extractor.glcm_params().symmetric;
        let mut row = Vec::new();
        let mut counts = Vec::new();
        for window in &episode.kept.glcm {
            window.counts(volume.levels, volume.range, symmetric, &mut counts);
            row.extend(extractor.haralick_row(&counts));
        }
        Ok(model.predict_extracted(&row)?)
    }

    /// Conditions the episode's last steps, then summarises it: the classification of its
    /// last window (all of it when shorter) and the decision.
    pub(super) fn end_episode(&mut self, ended_by: EpisodeEnd) -> Result<(), StreamError> {
        self.flush()?;
        let episode = self.episode.as_mut().expect("an episode is under way");
        let n = episode.steps;
        let whole = n.min(self.window);
        let last = match (&self.model, &mut episode.kept.network) {
            _ if whole < self.bin => None,
            (SavedModel::Spiking(m), Some(feed)) => {
                feed.flush(m.network());
                Some(decide(&feed.scores(m.network())))
            }
            (SavedModel::Features(m), _) => {
                let p = self.classify(m, n - whole, n)?;
                Some((m.class_index(&p.predicted), p.shares))
            }
            (SavedModel::Spiking(_), None) => unreachable!("a spiking model's episode runs it"),
        };
        let episode = self.episode.take().expect("an episode is under way");
        let decision = episode.decider.decision();
        self.events.push(Event::End(EpisodeSummary {
            duration_s: n as f64 / 1000.0,
            class: last.as_ref().map(|l| l.0),
            shares: last.map(|l| l.1),
            decision: decision.map(|d| d.0),
            decided_at_s: decision.map(|d| d.1),
            bins: episode.bins,
            ended_by,
        }));
        Ok(())
    }
}

/// Cells taken through all the stages of a step at a time: their values and state (some
/// 60 bytes per cell) stay in the first-level cache.
const PART: usize = 512;

/// One step of some cells to condition: their raw values, resting values, whether they
/// hold a taxel, the filter's state, and where the conditioned values go.
struct Conditioning<'a> {
    raw: &'a [f64],
    offsets: &'a [f64],
    present: &'a [bool],
    state: [&'a mut [f64]; 2],
    out: &'a mut [f64],
}

impl Conditioning<'_> {
    /// Removes the resting value (0 for masked cells), filters (the filter started in its
    /// steady state at the episode's first step) when there is a filter, and divides by
    /// the scale: the offline causal pipeline's operations in its order.
    fn run(self, filter: Option<&Butterworth2>, scale: f64, first: bool) {
        #[cfg(target_arch = "x86_64")]
        {
            /// The same loops with AVX2's four-lane division; no FMA, so the results are
            /// the portable path's bit for bit.
            #[target_feature(enable = "avx2")]
            unsafe fn run_avx2(
                cells: Conditioning<'_>,
                filter: Option<&Butterworth2>,
                scale: f64,
                first: bool,
            ) {
                cells.run_portable(filter, scale, first);
            }
            if neurotex_core::has_feature!("avx2") {
                // SAFETY: the CPU supports AVX2, checked just above.
                return unsafe { run_avx2(self, filter, scale, first) };
            }
        }
        self.run_portable(filter, scale, first);
    }

    #[inline(always)]
    fn run_portable(self, filter: Option<&Butterworth2>, scale: f64, first: bool) {
        let n = self.out.len();
        let (raw, offsets, present) = (&self.raw[..n], &self.offsets[..n], &self.present[..n]);
        let [z0, z1] = self.state;
        let (z0, z1, out) = (&mut z0[..n], &mut z1[..n], self.out);
        let input = |i: usize| if present[i] { raw[i] - offsets[i] } else { 0.0 };
        match filter {
            Some(f) => {
                if first {
                    for i in 0..n {
                        [z0[i], z1[i]] = f.steady_state(input(i));
                    }
                }
                for i in 0..n {
                    let mut z = [z0[i], z1[i]];
                    out[i] = f.step(input(i), &mut z) / scale;
                    [z0[i], z1[i]] = z;
                }
            }
            None => {
                for (i, x) in out.iter_mut().enumerate() {
                    *x = input(i) / scale;
                }
            }
        }
    }
}

/// `out = a + (b - a) * w`, cell by cell: the arithmetic of
/// [`crate::signal::resample_linear`].
fn interpolate(a: &[f64], b: &[f64], w: f64, out: &mut [f64]) {
    for ((o, &x), &y) in out.iter_mut().zip(a).zip(b) {
        *o = x + (y - x) * w;
    }
}

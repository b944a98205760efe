//! The spectrum of a spike train along the slide: spike counts in equal bins of the
//! travelled span, the magnitudes of their discrete Fourier transform, averaged in
//! logarithmically spaced bands of spatial frequency and compressed by `ln(1 + x)`.
//!
//! A texture read by sliding is a pattern in space; its spatial frequencies reach the
//! sensor as temporal frequencies scaled by the speed. Counting spikes in bins of travel
//! instead of time (Wang et al., Front. Neurorobot. 16:808222, 2022, resample the raw signal
//! to samples per millimetre for the same reason) puts the same texture's pattern at the same
//! frequency whatever the speed. The bands are spaced logarithmically so that the long
//! wavelengths, resolved by few transform bins, keep as much weight as the short ones,
//! resolved by many; the logarithm keeps a few strong bands from dominating a distance or a
//! linear model.
//!
//! The transform is computed directly (`bins x bins / 2` multiply-adds with a table of
//! twiddle factors) rather than by an FFT crate: with the default 128 bins it costs about
//! 8 000 multiply-adds per train, less than reading the train's spikes, and it keeps
//! the build free of a dependency with many SIMD back ends to compile.

/// Parameters of the spike-train spectrum.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpectrumParams {
    /// Equal bins the travelled span is cut into (a power of two is not needed).
    pub bins: usize,
    /// Logarithmically spaced bands (before merging the ones that fall on the same
    /// transform bin).
    pub bands: usize,
}

/// The most bins a spectrum may use: the direct transform's cost grows with the square.
pub const MAX_BINS: usize = 4096;

impl SpectrumParams {
    /// The band edges in transform bins, `[lo, hi)` between consecutive edges: frequency
    /// `k` (cycles over the span) for `k = 1 ..= bins / 2` rounded from
    /// `(bins / 2)^(i / bands)`, duplicates merged. The last band ends just below the
    /// Nyquist frequency `bins / 2`, whose bin holds only the alternation of neighbouring
    /// bins.
    pub fn edges(&self) -> Vec<usize> {
        let top = (self.bins / 2) as f64;
        let mut edges: Vec<usize> = (0..=self.bands)
            .map(|i| top.powf(i as f64 / self.bands as f64).round() as usize)
            .collect();
        edges.dedup();
        edges
    }

    /// How many bands a train's spectrum has.
    pub fn n_bands(&self) -> usize {
        self.edges().len().saturating_sub(1)
    }
}

/// A reusable transform for trains of one parameter set.
#[derive(Debug, Clone)]
pub struct Spectrum {
    bins: usize,
    edges: Vec<usize>,
    cos: Vec<f64>,
    sin: Vec<f64>,
}

impl Spectrum {
    /// The transform of `params`.
    ///
    /// # Panics
    /// If `bins` is below 8 or above [`MAX_BINS`], or `bands` is 0 (a caller bug: the
    /// pipeline checks both).
    pub fn new(params: SpectrumParams) -> Spectrum {
        assert!((8..=MAX_BINS).contains(&params.bins) && params.bands > 0);
        let n = params.bins;
        let angle = |j: usize| 2.0 * std::f64::consts::PI * j as f64 / n as f64;
        Spectrum {
            bins: n,
            edges: params.edges(),
            cos: (0..n).map(|j| angle(j).cos()).collect(),
            sin: (0..n).map(|j| angle(j).sin()).collect(),
        }
    }

    /// How many values [`Spectrum::train`] appends.
    pub fn n_bands(&self) -> usize {
        self.edges.len() - 1
    }

    /// Appends the band values of `train` (spike steps) over steps `0..n_steps` to `out`:
    /// `ln(1 + mean |X_k|)` over each band's frequencies `k`, where `X_k` is the transform
    /// of the spike counts in `bins` equal bins (spike at step `t` in bin
    /// `floor(t * bins / n_steps)`; spikes at or after `n_steps` are not counted). The
    /// mean count is not removed: it only changes `X_0`, which no band holds.
    ///
    /// # Panics
    /// If `n_steps` is 0.
    pub fn train(&self, train: &[u32], n_steps: usize, out: &mut Vec<f64>) {
        assert!(n_steps > 0);
        let n = self.bins;
        let mut counts = vec![0.0f64; n];
        for &t in train {
            let t = t as usize;
            if t < n_steps {
                counts[t * n / n_steps] += 1.0;
            }
        }
        self.binned(&counts, out);
    }

    /// Appends the band values of a sampled signal `x` (one taxel's, `x.len()` steps),
    /// resampled to the spectrum's bins by averaging the samples in each (sample `t` in
    /// bin `floor(t * bins / x.len())`), as [`Spectrum::train`] does with spike counts.
    ///
    /// # Panics
    /// If `x` has fewer samples than the spectrum has bins.
    pub fn signal(&self, x: &[f64], out: &mut Vec<f64>) {
        let (n, len) = (self.bins, x.len());
        assert!(len >= n);
        let mut sums = vec![0.0f64; n];
        let mut counts = vec![0usize; n];
        for (t, &v) in x.iter().enumerate() {
            let b = t * n / len;
            sums[b] += v;
            counts[b] += 1;
        }
        for (s, c) in sums.iter_mut().zip(&counts) {
            *s /= *c as f64;
        }
        self.binned(&sums, out);
    }

    /// Appends the band values of a series of exactly `bins` values.
    fn binned(&self, series: &[f64], out: &mut Vec<f64>) {
        let n = self.bins;
        let top = *self.edges.last().unwrap_or(&1);
        let mut magnitude = vec![0.0f64; top];
        for (k, m) in magnitude.iter_mut().enumerate().skip(1) {
            let (mut re, mut im) = (0.0, 0.0);
            let mut phase = 0usize;
            for &c in series {
                if c != 0.0 {
                    re += c * self.cos[phase];
                    im -= c * self.sin[phase];
                }
                phase += k;
                if phase >= n {
                    phase -= n;
                }
            }
            *m = re.hypot(im);
        }
        for w in self.edges.windows(2) {
            let band = &magnitude[w[0]..w[1]];
            out.push((band.iter().sum::<f64>() / band.len() as f64).ln_1p());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The transform by the definition, with complex exponentials from `f64::sin_cos`.
    fn slow_magnitudes(counts: &[f64]) -> Vec<f64> {
        let n = counts.len();
        (0..=n / 2)
            .map(|k| {
                let (mut re, mut im) = (0.0, 0.0);
                for (j, &c) in counts.iter().enumerate() {
                    let (s, co) =
                        (-2.0 * std::f64::consts::PI * (k * j) as f64 / n as f64).sin_cos();
                    re += c * co;
                    im += c * s;
                }
                re.hypot(im)
            })
            .collect()
    }

    #[test]
    fn edges_are_log_spaced_and_merged() {
        let p = SpectrumParams {
            bins: 128,
            bands: 16,
        };
        // 64^(i/16) = 2^(3i/8): 1, 1.30, 1.68, 2.18, 2.83, 3.67, 4.76, 6.17, 8, ...
        assert_eq!(
            p.edges(),
            vec![1, 2, 3, 4, 5, 6, 8, 10, 13, 17, 23, 29, 38, 49, 64]
        );
        assert_eq!(p.n_bands(), 14);
    }

    #[test]
    fn bands_equal_the_slow_transform_averaged() {
        let params = SpectrumParams { bins: 16, bands: 3 };
        let spectrum = Spectrum::new(params);
        // 40 steps into 16 bins: step t in bin floor(16 t / 40).
        let train = [0u32, 3, 4, 9, 17, 18, 25, 33, 39, 41];
        let mut counts = vec![0.0; 16];
        for &t in &train {
            if t < 40 {
                counts[t as usize * 16 / 40] += 1.0;
            }
        }
        let slow = slow_magnitudes(&counts);
        // 8^(i/3): 1, 2, 4, 8.
        assert_eq!(params.edges(), vec![1, 2, 4, 8]);
        let expect: Vec<f64> = [(1, 2), (2, 4), (4, 8)]
            .iter()
            .map(|&(a, b)| (slow[a..b].iter().sum::<f64>() / (b - a) as f64).ln_1p())
            .collect();
        let mut got = Vec::new();
        spectrum.train(&train, 40, &mut got);
        assert_eq!(got.len(), 3);
        for (g, e) in got.iter().zip(&expect) {
            assert!((g - e).abs() < 1e-12, "{got:?} vs {expect:?}");
        }
    }

    #[test]
    fn a_periodic_train_peaks_in_its_band() {
        // One spike every 8 bins of 128: 16 cycles over the span, in band [13, 17).
        let params = SpectrumParams {
            bins: 128,
            bands: 16,
        };
        let spectrum = Spectrum::new(params);
        let train: Vec<u32> = (0..16).map(|i| i * 80).collect();
        let mut got = Vec::new();
        spectrum.train(&train, 1280, &mut got);
        let peak = got
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .unwrap()
            .0;
        let edges = params.edges();
        assert!(edges[peak] <= 16 && 16 < edges[peak + 1], "{got:?}");
        // A perfect comb has nothing at frequencies that are not its harmonics.
        assert!(got[0].abs() < 1e-9, "{got:?}");
    }

    #[test]
    fn a_signal_is_averaged_into_bins_then_transformed_as_counts_are() {
        let spectrum = Spectrum::new(SpectrumParams { bins: 8, bands: 2 });
        // 20 samples into 8 bins: sample t in bin floor(8 t / 20), 2 or 3 samples each.
        let x: Vec<f64> = (0..20).map(|t| ((t * 7) % 5) as f64 - 1.5).collect();
        let mut means = vec![0.0; 8];
        let mut sizes = vec![0.0; 8];
        for (t, v) in x.iter().enumerate() {
            means[t * 8 / 20] += v;
            sizes[t * 8 / 20] += 1.0;
        }
        for (m, s) in means.iter_mut().zip(&sizes) {
            *m /= s;
        }
        let slow = slow_magnitudes(&means);
        // 4^(i/2): 1, 2, 4.
        let expect = [slow[1].ln_1p(), ((slow[2] + slow[3]) / 2.0).ln_1p()];
        let mut got = Vec::new();
        spectrum.signal(&x, &mut got);
        for (g, e) in got.iter().zip(&expect) {
            assert!((g - e).abs() < 1e-12, "{got:?} vs {expect:?}");
        }
    }

    #[test]
    fn an_empty_train_is_all_zero() {
        let spectrum = Spectrum::new(SpectrumParams {
            bins: 128,
            bands: 16,
        });
        let mut got = Vec::new();
        spectrum.train(&[], 1000, &mut got);
        assert!(got.iter().all(|&v| v == 0.0));
    }
}

//! Haralick features (Haralick, Shanmugam and Dinstein 1973; paper eqs. 5-8) of a
//! normalised co-occurrence matrix.

/// The paper's three features of a mean GLCM.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Haralick {
    /// `sum p(i,j) (i-j)^2`.
    pub contrast: f64,
    /// `sum p(i,j) (i-mu_x)(j-mu_y) / (sigma_x sigma_y)`; 1 when either sigma is below
    /// 1e-15 (the scikit-image convention), so never NaN.
    pub correlation: f64,
    /// Angular second moment `sum p(i,j)^2`.
    pub asm: f64,
}

impl Haralick {
    /// The features as `[contrast, correlation, asm]`.
    pub fn to_array(self) -> [f64; 3] {
        [self.contrast, self.correlation, self.asm]
    }
}

/// Features of the `levels x levels` count matrix `counts`, normalised by its total.
/// An all-zero matrix (no pairs at all) gives contrast 0, correlation 1, ASM 0.
///
/// # Panics
/// If `counts` is not square in `levels` (a caller bug).
pub fn haralick(counts: &[u32], levels: usize) -> Haralick {
    assert_eq!(counts.len(), levels * levels);
    let total: f64 = counts.iter().map(|&c| f64::from(c)).sum();
    if total == 0.0 {
        return Haralick {
            contrast: 0.0,
            correlation: 1.0,
            asm: 0.0,
        };
    }
    let inv = 1.0 / total;
    let (mut px, mut py) = (vec![0.0; levels], vec![0.0; levels]);
    let (mut contrast, mut asm) = (0.0, 0.0);
    for i in 0..levels {
        for j in 0..levels {
            let p = f64::from(counts[i * levels + j]) * inv;
            let d = i as f64 - j as f64;
            contrast += p * d * d;
            asm += p * p;
            px[i] += p;
            py[j] += p;
        }
    }
    let mean = |m: &[f64]| {
        m.iter()
            .enumerate()
            .map(|(i, &p)| i as f64 * p)
            .sum::<f64>()
    };
    let (mu_x, mu_y) = (mean(&px), mean(&py));
    let sd = |m: &[f64], mu: f64| {
        m.iter()
            .enumerate()
            .map(|(i, &p)| p * (i as f64 - mu).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let (sd_x, sd_y) = (sd(&px, mu_x), sd(&py, mu_y));
    let correlation = if sd_x < 1e-15 || sd_y < 1e-15 {
        1.0
    } else {
        let mut cov = 0.0;
        for i in 0..levels {
            for j in 0..levels {
                let p = f64::from(counts[i * levels + j]) * inv;
                cov += p * (i as f64 - mu_x) * (j as f64 - mu_y);
            }
        }
        cov / (sd_x * sd_y)
    };
    Haralick {
        contrast,
        correlation,
        asm,
    }
}

//! The values the paper reports, to stand beside ours when the data follow its design.
//!
//! The paper's speeds are those of its own rig, so the report sets these beside ours only
//! when [`super::ReportContext::paper_comparable`] says the data come from that design.

use crate::values::Speed;

/// The paper's E1 accuracies (%), single taxel and 3D-GLCM, by speed (table II).
pub const PAPER_E1: [(f64, f64, f64); 3] =
    [(5.0, 75.0, 92.0), (10.0, 73.0, 88.0), (15.0, 72.0, 84.0)];
/// The paper's 2D-GLCM accuracies (%) by speed (table III).
pub const PAPER_E4_2D: [(f64, f64); 3] = [(5.0, 46.0), (10.0, 33.0), (15.0, 43.0)];
/// The paper's speed-invariance accuracies (%), single taxel and 3D-GLCM, by test speed (table IV).
pub const PAPER_E6: [(f64, f64, f64); 3] =
    [(5.0, 28.0, 54.0), (10.0, 30.0, 51.0), (15.0, 27.0, 40.0)];
/// The paper's time to recognition: fraction of the slide at which 3D-GLCM matches the
/// single taxel, by speed (section IV-D; 10 mm/s is not stated).
pub const PAPER_E5: [(f64, f64); 2] = [(5.0, 0.3), (15.0, 0.7)];
/// The gain the paper chose after its ISI sweep over G = 5..20 (section II-E, "Neuronal Model").
pub const PAPER_GAIN: f64 = 8.0;
/// The number of textures the paper classified.
pub const PAPER_TEXTURES: usize = 8;

/// The paper's values, looked up by speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Paper {
    /// E1: `(speed, single taxel %, 3D-GLCM %)`.
    pub e1: &'static [(f64, f64, f64)],
    /// E4: `(speed, 2D-GLCM %)`.
    pub e4_2d: &'static [(f64, f64)],
    /// E5: `(speed, fraction of the slide)`.
    pub e5_first_match: &'static [(f64, f64)],
    /// E6: `(test speed, single taxel %, 3D-GLCM %)`.
    pub e6: &'static [(f64, f64, f64)],
    /// E7: the chosen gain.
    pub gain: f64,
    /// Textures classified.
    pub textures: usize,
}

/// The paper of Gupta, Nakagawa, Lepora and Thakor.
pub const PAPER: Paper = Paper {
    e1: &PAPER_E1,
    e4_2d: &PAPER_E4_2D,
    e5_first_match: &PAPER_E5,
    e6: &PAPER_E6,
    gain: PAPER_GAIN,
    textures: PAPER_TEXTURES,
};

/// Single-taxel and 3D-GLCM accuracies (%) the paper gives for one speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PaperPair {
    /// Single taxel, %.
    pub taxel: f64,
    /// 3D-GLCM, %.
    pub glcm3d: f64,
}

fn at<T: Copy>(table: &[(f64, T)], speed: Speed) -> Option<T> {
    table
        .iter()
        .find(|(s, _)| Speed::of(*s) == speed)
        .map(|&(_, v)| v)
}

fn pair_at(table: &[(f64, f64, f64)], speed: Speed) -> Option<PaperPair> {
    table
        .iter()
        .find(|(s, _, _)| Speed::of(*s) == speed)
        .map(|&(_, taxel, glcm3d)| PaperPair { taxel, glcm3d })
}

impl Paper {
    /// E1 at `speed`, if the paper gives it.
    pub fn e1_at(&self, speed: Speed) -> Option<PaperPair> {
        pair_at(self.e1, speed)
    }

    /// E4's 2D-GLCM accuracy (%) at `speed`, if the paper gives it.
    pub fn e4_2d_at(&self, speed: Speed) -> Option<f64> {
        at(self.e4_2d, speed)
    }

    /// E5's fraction of the slide at `speed`, if the paper gives it.
    pub fn e5_first_match_at(&self, speed: Speed) -> Option<f64> {
        at(self.e5_first_match, speed)
    }

    /// E6 with `speed` held out, if the paper gives it.
    pub fn e6_at(&self, speed: Speed) -> Option<PaperPair> {
        pair_at(self.e6, speed)
    }

    /// The speeds of the paper's rig, ascending.
    pub fn speeds(&self) -> Vec<Speed> {
        Speed::distinct(self.e1.iter().map(|p| Speed::of(p.0)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_are_found_by_speed_and_missing_ones_are_none() {
        let five = Speed::of(5.0);
        assert_eq!(
            PAPER.e1_at(five),
            Some(PaperPair {
                taxel: 75.0,
                glcm3d: 92.0
            })
        );
        assert_eq!(PAPER.e4_2d_at(Speed::of(10.0)), Some(33.0));
        assert_eq!(PAPER.e5_first_match_at(Speed::of(10.0)), None);
        assert_eq!(PAPER.e6_at(Speed::of(15.0)).map(|p| p.glcm3d), Some(40.0));
        assert_eq!(PAPER.e1_at(Speed::of(-5.0)), None);
        assert_eq!(PAPER.speeds().len(), 3);
    }
}

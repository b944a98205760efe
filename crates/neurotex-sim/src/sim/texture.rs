//! The eight textures of the paper as procedural height fields (mm), each with a compliance.
//!
//! Heights are functions of position on an unbounded surface; a trial's "new random patch"
//! is a random translation of that surface plus a per-trial seed for the random elements
//! (fibres, foam cells, roughness), so no two trials touch the same ground.

use serde::{Deserialize, Serialize};

/// The paper's textures, in the paper's order (figure 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Texture {
    /// Floor tile 1: a square grid of grooves.
    Ft1,
    /// Floor tile 2: parallel diagonal ridges.
    Ft2,
    /// Floor tile 3: small studs on a hexagonal lattice.
    Ft3,
    /// Rubber tile: large round studs on soft rubber.
    Rt,
    /// Textile rug: a plain weave of soft fibre bundles.
    TRug,
    /// Scotch brite: a random mat of stiff fibres over a spongy body.
    Sb,
    /// Corrugated paper: flutes across the sliding direction.
    Cp,
    /// Styrofoam: fused foam beads.
    Stf,
}

/// All eight textures in the paper's order.
pub const ALL_TEXTURES: [Texture; 8] = [
    Texture::Ft1,
    Texture::Ft2,
    Texture::Ft3,
    Texture::Rt,
    Texture::TRug,
    Texture::Sb,
    Texture::Cp,
    Texture::Stf,
];

impl Texture {
    /// The paper's abbreviation.
    pub fn name(self) -> &'static str {
        match self {
            Texture::Ft1 => "FT1",
            Texture::Ft2 => "FT2",
            Texture::Ft3 => "FT3",
            Texture::Rt => "RT",
            Texture::TRug => "TRug",
            Texture::Sb => "SB",
            Texture::Cp => "CP",
            Texture::Stf => "STF",
        }
    }

    /// The texture with abbreviation `name` (case-insensitive).
    pub fn from_name(name: &str) -> Option<Self> {
        ALL_TEXTURES
            .iter()
            .copied()
            .find(|t| t.name().eq_ignore_ascii_case(name))
    }

    /// Contact stiffness of the texture's surface layer per unit area, N/mm³ (a Winkler
    /// foundation): ceramic tiles are rigid; rug pile and scouring pad are very soft.
    pub fn stiffness_n_per_mm3(self) -> f64 {
        match self {
            Texture::Ft1 | Texture::Ft2 | Texture::Ft3 => 100.0,
            Texture::Rt => 0.2,
            Texture::TRug => 0.015,
            Texture::Sb => 0.01,
            Texture::Cp => 0.05,
            Texture::Stf => 0.1,
        }
    }

    /// Surface height in mm at `(x, y)` mm for the random elements drawn from `seed`.
    pub fn height(self, x: f64, y: f64, seed: u64) -> f64 {
        match self {
            Texture::Ft1 => {
                // 6 mm tiles separated by 1.5 mm wide, 0.5 mm deep grooves with rounded edges
                let g = |u: f64| {
                    let d = (u.rem_euclid(6.0) - 0.75).abs(); // distance from groove centre
                    smoothstep(0.5, 1.0, d)
                };
                -0.5 * (1.0 - g(x) * g(y)) + 0.02 * value_noise(x / 0.5, y / 0.5, seed)
            }
            Texture::Ft2 => {
                // 3 mm sinusoidal ridges at 45 degrees, 0.25 mm amplitude, fine roughness
                let u = (x + y) * std::f64::consts::FRAC_1_SQRT_2;
                0.25 * (std::f64::consts::TAU * u / 3.0).sin()
                    + 0.03 * value_noise(x / 0.4, y / 0.4, seed)
            }
            Texture::Ft3 => {
                // 1.5 mm studs, 0.3 mm high, on a hexagonal lattice of 4 mm pitch
                let d = hex_lattice_distance(x, y, 4.0);
                0.3 * (1.0 - smoothstep(0.5, 0.75, d)) + 0.02 * value_noise(x / 0.5, y / 0.5, seed)
            }
            Texture::Rt => {
                // 8 mm coin studs, 0.6 mm high, on a square lattice of 12 mm pitch
                let (cx, cy) = (x.rem_euclid(12.0) - 6.0, y.rem_euclid(12.0) - 6.0);
                let d = (cx * cx + cy * cy).sqrt();
                0.6 * (1.0 - smoothstep(3.6, 4.0, d)) + 0.03 * value_noise(x / 1.0, y / 1.0, seed)
            }
            Texture::TRug => {
                // plain weave, 2.5 mm pitch: warp and weft bundles alternating over and under,
                // with irregular fibre loops
                let p = 2.5;
                let (i, j) = ((x / p).floor() as i64, (y / p).floor() as i64);
                let (fx, fy) = (x / p - i as f64, y / p - j as f64);
                let over_warp = (i + j).rem_euclid(2) == 0;
                let bump = |f: f64| (std::f64::consts::PI * f).sin();
                let warp = bump(fx) * if over_warp { 1.0 } else { 0.5 };
                let weft = bump(fy) * if over_warp { 0.5 } else { 1.0 };
                0.4 * warp.max(weft) + 0.2 * value_noise(x / 0.8, y / 0.8, seed)
            }
            Texture::Sb => 0.5 * fibre_mat(x, y, seed),
            Texture::Cp => {
                // 7 mm flutes across the sliding direction, 0.8 mm amplitude, slightly
                // irregular pitch from the forming process
                let wobble = 0.3 * value_noise(0.0, y / 20.0, seed);
                0.8 * (0.5 + 0.5 * (std::f64::consts::TAU * (x + wobble) / 7.0).cos()).powf(1.5)
            }
            Texture::Stf => {
                // fused beads of about 3 mm: domes over Voronoi cells with crevices between
                let (f1, f2) = worley(x / 3.0, y / 3.0, seed);
                let edge = smoothstep(0.0, 0.15, f2 - f1);
                0.35 * (1.0 - f1 * f1).max(0.0) * edge
            }
        }
    }
}

fn smoothstep(a: f64, b: f64, x: f64) -> f64 {
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// SplitMix64: a well-mixed 64-bit hash of lattice coordinates and seed.
pub(crate) fn hash3(a: i64, b: i64, seed: u64) -> u64 {
    let mut z = seed
        .wrapping_add((a as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15))
        .wrapping_add((b as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A uniform number in [0, 1) from a hash.
pub(crate) fn unit(h: u64) -> f64 {
    (h >> 11) as f64 / (1u64 << 53) as f64
}

/// Smooth value noise in [-1, 1] on a unit lattice.
fn value_noise(x: f64, y: f64, seed: u64) -> f64 {
    let (i, j) = (x.floor() as i64, y.floor() as i64);
    let (fx, fy) = (x - i as f64, y - j as f64);
    let (sx, sy) = (fx * fx * (3.0 - 2.0 * fx), fy * fy * (3.0 - 2.0 * fy));
    let v = |a: i64, b: i64| 2.0 * unit(hash3(a, b, seed)) - 1.0;
    let top = v(i, j) + (v(i + 1, j) - v(i, j)) * sx;
    let bottom = v(i, j + 1) + (v(i + 1, j + 1) - v(i, j + 1)) * sx;
    top + (bottom - top) * sy
}

/// Distance (mm) to the nearest point of a hexagonal lattice of pitch `p`.
fn hex_lattice_distance(x: f64, y: f64, p: f64) -> f64 {
    let h = p * 3f64.sqrt() / 2.0;
    let row = (y / h).round();
    let mut best = f64::INFINITY;
    for dr in -1..=1 {
        let r = row + dr as f64;
        let shift = if (r as i64).rem_euclid(2) == 1 {
            p / 2.0
        } else {
            0.0
        };
        let cx = ((x - shift) / p).round() * p + shift;
        let (dx, dy) = (x - cx, y - r * h);
        best = best.min((dx * dx + dy * dy).sqrt());
    }
    best
}

/// Distances to the nearest and second-nearest jittered lattice point (Worley noise).
fn worley(x: f64, y: f64, seed: u64) -> (f64, f64) {
    let (i, j) = (x.floor() as i64, y.floor() as i64);
    let (mut f1, mut f2) = (f64::INFINITY, f64::INFINITY);
    for a in i - 1..=i + 1 {
        for b in j - 1..=j + 1 {
            let h = hash3(a, b, seed);
            let (px, py) = (a as f64 + unit(h), b as f64 + unit(h.rotate_left(29)));
            let d = ((x - px).powi(2) + (y - py).powi(2)).sqrt();
            if d < f1 {
                f2 = f1;
                f1 = d;
            } else if d < f2 {
                f2 = d;
            }
        }
    }
    (f1, f2)
}

/// A random mat of straight fibres (0.3 mm thick, 3 per 4 mm cell, random directions):
/// the height is the tallest fibre profile covering the point, in [0, 1].
fn fibre_mat(x: f64, y: f64, seed: u64) -> f64 {
    let (i, j) = fibre_cell(x, y);
    fibre_height(x, y, &neighbourhood_fibres(i, j, seed))
}

/// Side of a cell of the fibre mat, mm.
const FIBRE_CELL_MM: f64 = 4.0;

/// The cell of the fibre mat holding `(x, y)`.
fn fibre_cell(x: f64, y: f64) -> (i64, i64) {
    (
        (x / FIBRE_CELL_MM).floor() as i64,
        (y / FIBRE_CELL_MM).floor() as i64,
    )
}

/// One fibre of the mat: its centre (mm), its direction (a unit vector) and its height.
#[derive(Debug, Clone, Copy, Default)]
struct Fibre {
    cx: f64,
    cy: f64,
    dx: f64,
    dy: f64,
    level: f64,
}

/// The fibres of the 3x3 cells around cell `(i, j)`, the ones a point of that cell may
/// touch, in the order their heights are compared.
fn neighbourhood_fibres(i: i64, j: i64, seed: u64) -> [Fibre; 27] {
    let mut out = [Fibre::default(); 27];
    let mut next = out.iter_mut();
    for a in i - 1..=i + 1 {
        for b in j - 1..=j + 1 {
            let base = hash3(a, b, seed ^ 0x5B5B);
            for k in 0..3u32 {
                let r =
                    base.rotate_left(k * 21 + 7) ^ (k as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
                let r = hash3(r as i64, k as i64, seed);
                // A random direction without trigonometry: the rational parametrisation of
                // the half circle, (1 - q^2, 2q) / (1 + q^2) with q uniform in [-1, 1)
                // (directions are spread over 180 degrees, denser near the axis).
                let q = 2.0 * unit(r.rotate_left(34)) - 1.0;
                let norm = 1.0 / (1.0 + q * q);
                *next.next().expect("27 fibres") = Fibre {
                    cx: (a as f64 + unit(r)) * FIBRE_CELL_MM,
                    cy: (b as f64 + unit(r.rotate_left(17))) * FIBRE_CELL_MM,
                    dx: (1.0 - q * q) * norm,
                    dy: 2.0 * q * norm,
                    level: 0.6 + 0.4 * unit(r.rotate_left(51)),
                };
            }
        }
    }
    out
}

/// The tallest profile of `fibres` at `(x, y)`: each fibre is 10 mm long and its edge
/// falls off between 0.1 and 0.15 mm from its axis.
fn fibre_height(x: f64, y: f64, fibres: &[Fibre]) -> f64 {
    let mut h: f64 = 0.0;
    for f in fibres {
        let (px, py) = (x - f.cx, y - f.cy);
        let along = px * f.dx + py * f.dy;
        if along.abs() > 5.0 {
            continue;
        }
        let across = (px * f.dy - py * f.dx).abs();
        h = h.max(f.level * (1.0 - smoothstep(0.1, 0.15, across)));
    }
    h
}

/// A texture's surface for one trial's seed, sampled point after point along a line: the
/// heights of [`Texture::height`], bit for bit, but the scotch-brite mat's fibres around
/// the last point's cell are kept for the next point (a 0.2 mm step stays in one 4 mm
/// cell about 20 times running), where `height` draws all 27 again for every point.
pub(crate) struct Surface {
    texture: Texture,
    seed: u64,
    /// The cell whose neighbourhood's fibres `fibres` holds.
    cell: Option<(i64, i64)>,
    fibres: FibreLanes,
}

/// The 27 fibres of a neighbourhood as one array per field (structure of arrays), padded
/// to 28 with a fibre of height 0, so four fibres are evaluated per AVX instruction.
#[derive(Default)]
struct FibreLanes {
    cx: [f64; 28],
    cy: [f64; 28],
    dx: [f64; 28],
    dy: [f64; 28],
    level: [f64; 28],
}

impl FibreLanes {
    fn new(fibres: &[Fibre; 27]) -> Self {
        let mut lanes = FibreLanes::default();
        for (k, f) in fibres.iter().enumerate() {
            (lanes.cx[k], lanes.cy[k]) = (f.cx, f.cy);
            (lanes.dx[k], lanes.dy[k]) = (f.dx, f.dy);
            lanes.level[k] = f.level;
        }
        lanes
    }

    /// [`fibre_height`] of these fibres at `(x, y)`, equal bit for bit.
    fn height(&self, x: f64, y: f64) -> f64 {
        #[cfg(target_arch = "x86_64")]
        {
            if neurotex_core::has_feature!("avx") {
                // SAFETY: the CPU supports AVX, the only feature the function enables.
                return unsafe { self.height_avx(x, y) };
            }
        }
        self.height_lanes(x, y)
    }

    /// [`FibreLanes::height_lanes`] compiled for AVX (no FMA, so no operation rounds
    /// differently from the scalar code).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn height_avx(&self, x: f64, y: f64) -> f64 {
        self.height_lanes(x, y)
    }

    /// The tallest profile, without branches: a fibre out of reach counts as height 0,
    /// which changes nothing, since every profile is at least +0 and the maximum of
    /// such numbers does not depend on the order they are compared in; so four running
    /// maxima (one per lane) give [`fibre_height`]'s result exactly.
    #[inline(always)]
    fn height_lanes(&self, x: f64, y: f64) -> f64 {
        let mut tallest = [0.0f64; 4];
        for k in (0..28).step_by(4) {
            for (lane, h) in tallest.iter_mut().enumerate() {
                let i = k + lane;
                let (px, py) = (x - self.cx[i], y - self.cy[i]);
                let along = px * self.dx[i] + py * self.dy[i];
                let across = (px * self.dy[i] - py * self.dx[i]).abs();
                let profile = self.level[i] * (1.0 - smoothstep(0.1, 0.15, across));
                let profile = if along.abs() > 5.0 { 0.0 } else { profile };
                *h = h.max(profile);
            }
        }
        tallest.into_iter().fold(0.0, f64::max)
    }
}

impl Surface {
    /// `texture`'s surface with the random elements drawn from `seed`.
    pub(crate) fn new(texture: Texture, seed: u64) -> Self {
        Surface {
            texture,
            seed,
            cell: None,
            fibres: FibreLanes::default(),
        }
    }

    /// Surface height in mm at `(x, y)` mm, equal to `texture.height(x, y, seed)`.
    pub(crate) fn height(&mut self, x: f64, y: f64) -> f64 {
        if self.texture != Texture::Sb {
            return self.texture.height(x, y, self.seed);
        }
        let cell = fibre_cell(x, y);
        if self.cell != Some(cell) {
            self.fibres = FibreLanes::new(&neighbourhood_fibres(cell.0, cell.1, self.seed));
            self.cell = Some(cell);
        }
        0.5 * self.fibres.height(x, y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cached, four-lane fibre mat gives `Texture::height`'s bits on a path crossing
    /// many cells, back and forth (so the cache is both reused and replaced).
    #[test]
    fn surface_heights_equal_texture_heights_bit_for_bit() {
        for seed in [0, 7, 0xDEAD_BEEF] {
            let mut surface = Surface::new(Texture::Sb, seed);
            for k in 0..3000 {
                let along = (k % 1000) as f64 * 0.07 - 20.0;
                let (x, y) = (
                    123.4 + along * 0.99,
                    -56.7 + along * 0.05 + (k / 1000) as f64,
                );
                assert_eq!(
                    surface.height(x, y).to_bits(),
                    Texture::Sb.height(x, y, seed).to_bits(),
                    "seed {seed}, point {k}"
                );
            }
        }
    }
}

//! Alias-method sampling (Walker 1977, Vose 1991): a draw costs one table look-up instead of a
//! search through a cdf, for renderers that take millions of map samples per second.
//!
//! [`EnvAliasDistribution`] is built from an [`EnvDistribution`] and has the same texel
//! probabilities, the same pdf and the same placement of a sample inside its texel (uniform in
//! phi and cos theta); only the mapping from random numbers to texels differs. That mapping is
//! not monotonic, so it has no inverse: [`EnvDistribution`] keeps `invert_dir_sample`.
//!
//! Texel pdfs sit in their own array, a quarter of the bins' size, so the pdf of a direction
//! (the MIS weight of every BRDF sample) stays in cache far more often. A column bin carries
//! the pdf of its alias, so a draw reads the small row table (cache resident), one 16-byte bin
//! and, at an address known before the bin arrives, its own texel's pdf.

use crate::distribution::{DirSample, EnvDistribution, ONE_MINUS_EPSILON, texel_point};
use crate::latlong::latlong_dir_to_uv;
use glam::{Vec2, Vec3};

/// One bin of a 1D alias table: keep the bin's own cell with probability `q`, else `alias`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct AliasBin {
    /// Probability of the bin's own cell when the bin is drawn.
    q: f32,
    /// The other cell of the bin.
    alias: u32,
}

/// A discrete distribution over cells `0..n` with O(1) sampling.
#[derive(Clone, Debug)]
pub struct AliasTable {
    bins: Vec<AliasBin>,
}

/// Vose's construction in f64. Non-finite and negative weights count as zero; all-zero
/// weights give the uniform distribution. A zero-weight cell is never drawn.
fn build(weights: &[f64]) -> Vec<AliasBin> {
    let n = weights.len();
    let clean = |w: f64| if w.is_finite() && w > 0.0 { w } else { 0.0 };
    let total: f64 = weights.iter().map(|&w| clean(w)).sum();
    if !(total.is_finite() && total > 0.0) {
        return (0..n).map(|k| AliasBin { q: 1.0, alias: k as u32 }).collect();
    }
    let mut p: Vec<f64> = weights.iter().map(|&w| clean(w) * n as f64 / total).collect();
    let mut bins: Vec<AliasBin> = (0..n).map(|k| AliasBin { q: 1.0, alias: k as u32 }).collect();
    let (mut small, mut large): (Vec<usize>, Vec<usize>) = (0..n).partition(|&k| p[k] < 1.0);
    while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
        small.pop();
        bins[s] = AliasBin { q: p[s] as f32, alias: l as u32 };
        p[l] = (p[l] + p[s]) - 1.0;
        if p[l] < 1.0 {
            large.pop();
            small.push(l);
        }
    }
    // What is left holds probability 1 up to rounding, except a zero cell stranded by rounding:
    // that one must still never be drawn.
    let heaviest = (0..n).max_by(|&a, &b| weights[a].total_cmp(&weights[b])).unwrap_or(0);
    for k in small.into_iter().chain(large) {
        bins[k] = if clean(weights[k]) > 0.0 {
            AliasBin { q: 1.0, alias: k as u32 }
        } else {
            AliasBin { q: 0.0, alias: heaviest as u32 }
        };
    }
    bins
}

/// Draws bin `k` of `n` with `u` and resolves it through `bin(k)`: (k, the cell, `u` remapped
/// to a fresh uniform number in [0, 1) with about 24 - log2(n) bits, whether it was the alias).
#[inline]
fn draw(n: usize, u: f32, bin: impl Fn(usize) -> AliasBin) -> (usize, usize, f32, bool) {
    let x = f64::from(u.clamp(0.0, ONE_MINUS_EPSILON)) * n as f64;
    let k = (x as usize).min(n - 1);
    let r = (x - k as f64) as f32;
    let b = bin(k);
    // Selects, not branches: `b` is often a cache miss, and a mispredicted branch on it would
    // stall the independent work that follows until it arrives.
    let own = r < b.q;
    let (offset, width) = if own { (0.0, b.q) } else { (b.q, 1.0 - b.q) };
    let cell = if own { k } else { b.alias as usize };
    (k, cell, ((r - offset) / width).clamp(0.0, ONE_MINUS_EPSILON), !own)
}

impl AliasTable {
    /// The table of `weights` (at least one).
    ///
    /// # Panics
    /// When `weights` is empty.
    #[must_use]
    pub fn new(weights: &[f64]) -> Self {
        assert!(!weights.is_empty(), "an alias table needs at least one cell");
        Self { bins: build(weights) }
    }

    /// Number of cells.
    #[must_use]
    pub fn len(&self) -> usize {
        self.bins.len()
    }

    /// Never: a table has at least one cell.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        false
    }

    /// A cell drawn with `u` in [0, 1), and `u` remapped to a fresh uniform number in [0, 1).
    #[inline]
    #[must_use]
    pub fn sample(&self, u: f32) -> (usize, f32) {
        let (_, cell, r, _) = draw(self.bins.len(), u, |k| self.bins[k]);
        (cell, r)
    }

    /// Probability of cell `k`, recovered from the bins (O(n): for tests).
    #[must_use]
    pub fn probability(&self, k: usize) -> f64 {
        let n = self.bins.len() as f64;
        let own = f64::from(self.bins[k].q);
        let aliased: f64 = self.bins.iter().filter(|b| b.alias as usize == k).map(|b| 1.0 - f64::from(b.q)).sum();
        let aliased = if self.bins[k].alias as usize == k { aliased - (1.0 - own) } else { aliased };
        (own + aliased) / n
    }
}

/// A column bin of [`EnvAliasDistribution`]: the alias choice plus the alias's pdf (aligned so
/// a bin never straddles two cache lines).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(16))]
struct ColumnBin {
    bin: AliasBin,
    alias_pdf: f32,
}

/// Importance sampling of a lat-long map by alias tables: a row, then a column within it.
///
/// ```
/// use envmap_sphere::{EnvAliasDistribution, EnvDistribution};
/// use glam::Vec2;
/// let cdf = EnvDistribution::new(&envmap_sphere::default_map());
/// let alias = EnvAliasDistribution::new(&cdf);
/// let s = alias.sample_dir(Vec2::new(0.3, 0.7));
/// assert_eq!(s.pdf, cdf.uv_pdf(s.uv)); // same pdf as the cdf distribution
/// ```
#[derive(Clone, Debug)]
pub struct EnvAliasDistribution {
    width: u32,
    height: u32,
    rows: AliasTable,
    cols: Vec<ColumnBin>,
    /// texel pdfs per steradian, row-major
    pdfs: Vec<f32>,
    row_cos: Vec<(f64, f64)>,
    complete: bool,
}

impl EnvAliasDistribution {
    /// The alias form of `dist`: the same texel probabilities and pdf.
    #[must_use]
    pub fn new(dist: &EnvDistribution) -> Self {
        let (w, h) = dist.size();
        let rows = AliasTable::new(&(0..h as usize).map(|j| dist.row_probability(j)).collect::<Vec<_>>());
        let mut cols = Vec::with_capacity(w as usize * h as usize);
        let mut weights = vec![0.0; w as usize];
        for j in 0..h as usize {
            weights.iter_mut().enumerate().for_each(|(i, x)| *x = dist.column_probability(j, i));
            cols.extend(
                build(&weights)
                    .into_iter()
                    .map(|bin| ColumnBin { bin, alias_pdf: dist.texel_pdf(bin.alias as usize, j) }),
            );
        }
        let pdfs = (0..h as usize).flat_map(|j| (0..w as usize).map(move |i| dist.texel_pdf(i, j))).collect();
        Self { width: w, height: h, rows, cols, pdfs, row_cos: dist.row_cos().to_vec(), complete: dist.is_complete() }
    }

    /// [`EnvDistribution::is_complete`] of the distribution this was built from.
    #[must_use]
    pub fn is_complete(&self) -> bool {
        self.complete
    }

    /// A direction drawn with `u` in [0, 1)^2 ([`EnvDistribution::sample_dir`]'s contract:
    /// `uv` inside the drawn texel, `pdf` that texel's, per steradian).
    #[inline]
    #[must_use]
    pub fn sample_dir(&self, u: Vec2) -> DirSample {
        let (j, t) = self.rows.sample(u.y);
        let (w, h) = (self.width as usize, self.height as usize);
        let row = &self.cols[j * w..(j + 1) * w];
        let (k, i, s, aliased) = draw(w, u.x, |k| row[k].bin);
        let pdf = if aliased { row[k].alias_pdf } else { self.pdfs[j * w + k] };
        texel_point([w, h], &self.row_cos, [i, j], [s, t], pdf)
    }

    /// The pdf per steradian of drawing `dir`.
    #[must_use]
    pub fn dir_pdf(&self, dir: Vec3) -> f32 {
        self.uv_pdf(latlong_dir_to_uv(dir.normalize_or(Vec3::Y)))
    }

    /// The pdf per steradian at lat-long coordinates `uv` (the pdf of the texel containing it).
    #[inline]
    #[must_use]
    pub fn uv_pdf(&self, uv: Vec2) -> f32 {
        let (i, j) = crate::latlong::latlong_uv_to_texel(uv, self.width, self.height);
        self.pdfs[j as usize * self.width as usize + i as usize]
    }
}

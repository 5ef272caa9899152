//! Summed-area tables with f64 sums, for O(1) sums over texel rectangles (region energy in
//! median cut, cap bounds in centre-surround filtering).

use crate::color::luminance;
use crate::envmap::EnvMap;

/// A summed-area table of `C` channels over a `width` x `height` grid, sums in f64.
///
/// ```
/// use envmap_sphere::SummedAreaTable;
/// let sat = SummedAreaTable::<1>::from_fn(4, 3, |i, j| [f64::from(i + j)]);
/// assert_eq!(sat.sum(1, 0, 3, 2)[0], 1.0 + 2.0 + 2.0 + 3.0);
/// // a range that wraps across the seam: columns 3 and 0
/// assert_eq!(sat.sum_wrapped(3, 0, 1, 2)[0], 3.0 + 0.0 + 4.0 + 1.0);
/// ```
#[derive(Clone, Debug)]
pub struct SummedAreaTable<const C: usize> {
    width: u32,
    height: u32,
    /// (width + 1) x (height + 1) prefix sums; row 0 and column 0 are zero.
    table: Vec<[f64; C]>,
}

impl<const C: usize> SummedAreaTable<C> {
    /// Builds the table of `f(i, j)` over the grid.
    #[must_use]
    pub fn from_fn(width: u32, height: u32, f: impl Fn(u32, u32) -> [f64; C]) -> Self {
        let stride = width as usize + 1;
        let mut table = vec![[0.0; C]; stride * (height as usize + 1)];
        for j in 0..height as usize {
            let mut row = [0.0; C];
            for i in 0..width as usize {
                let v = f(i as u32, j as u32);
                for c in 0..C {
                    row[c] += v[c];
                    table[(j + 1) * stride + i + 1][c] = table[j * stride + i + 1][c] + row[c];
                }
            }
        }
        Self { width, height, table }
    }

    /// Grid width.
    #[must_use]
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Grid height.
    #[must_use]
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Sum over columns `x0..x1` and rows `y0..y1` (half-open; clamped to the grid).
    #[must_use]
    pub fn sum(&self, x0: u32, y0: u32, x1: u32, y1: u32) -> [f64; C] {
        let (x0, x1) = (x0.min(self.width) as usize, x1.min(self.width) as usize);
        let (y0, y1) = (y0.min(self.height) as usize, y1.min(self.height) as usize);
        if x0 >= x1 || y0 >= y1 {
            return [0.0; C];
        }
        let s = self.width as usize + 1;
        let t = &self.table;
        std::array::from_fn(|c| t[y1 * s + x1][c] - t[y0 * s + x1][c] - t[y1 * s + x0][c] + t[y0 * s + x0][c])
    }

    /// Like [`SummedAreaTable::sum`], but a column range with `x0 > x1` wraps across the seam:
    /// it covers `x0..width` and `0..x1`.
    #[must_use]
    pub fn sum_wrapped(&self, x0: u32, y0: u32, x1: u32, y1: u32) -> [f64; C] {
        if x0 <= x1 {
            self.sum(x0, y0, x1, y1)
        } else {
            let a = self.sum(x0, y0, self.width, y1);
            let b = self.sum(0, y0, x1, y1);
            std::array::from_fn(|c| a[c] + b[c])
        }
    }
}

impl SummedAreaTable<1> {
    /// Table of luminance x texel solid angle: region sums are luminous "power" (Y integrated
    /// over solid angle).
    #[must_use]
    pub fn luminance_power(map: &EnvMap) -> Self {
        let sa = map.row_solid_angles();
        Self::from_fn(map.width(), map.height(), |i, j| [f64::from(luminance(map.pixel(i, j))) * sa[j as usize]])
    }
}

impl SummedAreaTable<3> {
    /// Table of RGB radiance x texel solid angle: region sums are RGB power.
    #[must_use]
    pub fn rgb_power(map: &EnvMap) -> Self {
        let sa = map.row_solid_angles();
        Self::from_fn(map.width(), map.height(), |i, j| (map.pixel(i, j).as_dvec3() * sa[j as usize]).to_array())
    }
}

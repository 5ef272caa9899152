//! `envshadow info PATH [--json]`: what a map is and holds.

use envmap_sphere::{EnvMap, LoadOptions, LoadReport, Sh9};
use serde::Serialize;
use std::path::Path;

/// The `--json` object; field names are the documented keys.
#[derive(Serialize)]
pub struct MapInfo {
    pub width: u32,
    pub height: u32,
    pub format: &'static str,
    pub compression: String,
    /// The file's primaries (red, green, blue, white xy) when its pixels were converted from
    /// them to Rec.709; null otherwise.
    pub converted_from_primaries: Option<[[f32; 2]; 4]>,
    pub max_luminance: f32,
    pub mean_luminance: f64,
    pub power: [f64; 3],
    pub sh9: [[f32; 3]; 9],
}

impl MapInfo {
    pub fn new(map: &EnvMap, report: &LoadReport) -> Self {
        let stats = map.luminance_stats();
        let sh = Sh9::project(map);
        Self {
            width: map.width(),
            height: map.height(),
            format: report.format.name(),
            compression: report.compression.clone(),
            converted_from_primaries: report.converted_from.map(|c| [c.red, c.green, c.blue, c.white]),
            max_luminance: stats.max,
            mean_luminance: stats.mean_per_pixel,
            power: map.power(),
            sh9: sh.coeffs.map(|c| c.to_array()),
        }
    }

    /// Human-readable lines.
    pub fn print_text(&self, name: &str, map: &EnvMap, report: &LoadReport) {
        let stats = map.luminance_stats();
        outln!("{name}");
        outln!("  size          {} x {}", self.width, self.height);
        outln!("  format        {} ({})", self.format, self.compression);
        if let Some([r, g, b, w]) = self.converted_from_primaries {
            outln!("  primaries     converted to Rec.709 from R {r:?} G {g:?} B {b:?} white {w:?} (same CIE XYZ)");
        }
        outln!(
            "  luminance     max {:.6}, mean {:.6} per pixel, {:.6} per sr",
            self.max_luminance,
            self.mean_luminance,
            stats.mean_per_sr
        );
        outln!(
            "  percentiles   50%: {:.4}  90%: {:.4}  98%: {:.4}  99.9%: {:.4}",
            stats.percentile(50.0),
            stats.percentile(90.0),
            stats.percentile(98.0),
            stats.percentile(99.9)
        );
        outln!(
            "  power         [{:.6}, {:.6}, {:.6}] (integral of radiance over the sphere)",
            self.power[0],
            self.power[1],
            self.power[2]
        );
        let labels = ["l0", "l1 m-1", "l1 m0", "l1 m1", "l2 m-2", "l2 m-1", "l2 m0", "l2 m1", "l2 m2"];
        for (label, c) in labels.iter().zip(&self.sh9) {
            outln!("  sh9 {label:<7}  [{:+.6}, {:+.6}, {:+.6}]", c[0], c[1], c[2]);
        }
        if report.negatives_clamped > 0 {
            outln!(
                "  clamped       {} negative values to zero ({:.3e} of the power)",
                report.negatives_clamped,
                report.negative_power_fraction
            );
        }
        for w in &report.warnings {
            outln!("  warning       {w}");
        }
    }
}

pub(crate) fn run(path: &Path, json: bool) -> Result<(), String> {
    let (map, report) = EnvMap::load_with(path, &LoadOptions::default()).map_err(|e| e.to_string())?;
    let info = MapInfo::new(&map, &report);
    if json {
        outln!("{}", serde_json::to_string(&info).map_err(|e| e.to_string())?);
    } else {
        info.print_text(&path.display().to_string(), &map, &report);
    }
    Ok(())
}

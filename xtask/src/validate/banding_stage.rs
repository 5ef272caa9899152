//! Validate's banding stage (`--interleaved`): what paper 001's interleaved light sets remove
//! (shadow-boundary banding) and what they cost (noise, shadow work), measured on a wall lit by
//! this run's lights against the map's own truth (`trade::banding`); the report's section.

use envmap_sphere::{EnvMap, Tonemap};
use gpu::Gpu;
use light_extract::Decomposition;
use std::fmt::Write as _;
use trade::{BandingCase, BandingRow, Interleave, Shadow, measure_banding};

use crate::common::WritePng;

/// The stage's results.
pub(super) struct BandingStage {
    pub(super) size: (u32, u32),
    pub(super) case: BandingCase,
    pub(super) rows: Vec<BandingRow>,
    pub(super) supersample: u32,
}

/// What is measured: hard maps without, with paper 001's and with wider interleaving; wedges
/// without and with paper 001's.
fn settings(map_resolution: u32) -> Vec<(Shadow, Interleave)> {
    let maps = Shadow::Maps { resolution: map_resolution, pcf: 1 };
    let wider = Interleave { sets: Interleave::PAPER.sets, jitter: 0.3 };
    vec![
        (maps, Interleave::NONE),
        (maps, Interleave::PAPER),
        (maps, wider),
        (Shadow::Wedges, Interleave::NONE),
        (Shadow::Wedges, Interleave::PAPER),
    ]
}

/// Runs the stage at the run's width and a quarter of its height (the wall's edges run down
/// the columns: rows only average), with the run's shadow-map resolution and rotated grid.
pub(super) fn run(
    gpu: &Gpu,
    map: &EnvMap,
    decomposition: &Decomposition,
    (width, height): (u32, u32),
    map_resolution: u32,
    supersample: u32,
) -> Result<BandingStage, String> {
    let size = (width, (height / 4).max(8));
    let case = BandingCase::new(map, decomposition, size).map_err(|e| e.to_string())?;
    let passes = trade::Passes::new(gpu).map_err(|e| e.to_string())?;
    let settings = settings(map_resolution);
    // pipelines compile on a first frame: one untimed
    if let Some((shadow, interleave)) = settings.first() {
        measure_banding(gpu, &passes, &case, shadow, *interleave, supersample).map_err(|e| e.to_string())?;
    }
    let rows = settings
        .iter()
        .map(|(shadow, interleave)| measure_banding(gpu, &passes, &case, shadow, *interleave, supersample))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| e.to_string())?;
    Ok(BandingStage { size, case, rows, supersample })
}

impl BandingStage {
    /// One line per row, for the console.
    pub(super) fn lines(&self) -> Vec<String> {
        self.rows
            .iter()
            .map(|r| {
                let figures = r.banding.map_or_else(
                    || "no contrast to measure".to_string(),
                    |b| {
                        format!(
                            "largest step {:.3} (truth {:.3}), {} visible steps, noise {:.4}",
                            b.largest_step, b.truth_largest_step, b.visible_steps, b.noise
                        )
                    },
                );
                format!(
                    "  banding {:<16} sets {:<8} {figures}; shadows {:.1} ms, frame {:.1} ms",
                    r.technique,
                    r.interleave.name(),
                    r.shadow_ms,
                    r.frame_ms
                )
            })
            .collect()
    }

    /// The report's section: the case, the table and each frame.
    pub(super) fn html(&self, png: &WritePng) -> Result<String, String> {
        let mut s = String::new();
        let f = self.case.facing;
        let _ = write!(
            s,
            "<h2>Shadow-boundary banding and interleaved light sets (paper 001, section 3.5)</h2><p>A long wall on a Lambertian ground (albedo {}), turned to face the strongest light on the ground (direction [{:.3}, {:.3}, {:.3}], half-angle {:.2}°), seen from straight above at {}x{} ({} columns measured), rotated grid k = {}: every shadow edge runs down the columns. The truth per column is the map itself, integrated over every direction with ray-traced visibility (no lights, no noise). Figures are in units of the truth's contrast across the columns, on the profile (mean down each column) box-filtered over the interleaving tile's width (4 columns); a step is a jump of the profile over 4 columns beyond the truth's largest within 2 columns, visible when beyond Weber's 2 % of the darker side; noise is the image's RMS about its column means. Every light is shadowed.</p>",
            trade::banding::GROUND_ALBEDO,
            f.direction.x,
            f.direction.y,
            f.direction.z,
            f.half_angle().to_degrees(),
            self.size.0,
            self.size.1,
            self.case.columns(),
            self.supersample,
        );
        s.push_str("<table><tr><th>technique</th><th>light sets</th><th>largest step</th><th>truth's largest step</th><th>visible steps</th><th>profile RMSE</th><th>noise</th><th>shadow ms</th><th>frame ms</th></tr>");
        for r in &self.rows {
            let _ = write!(s, "<tr><td>{}</td><td>{}</td>", r.technique, r.interleave.name());
            match r.banding {
                Some(b) => {
                    let _ = write!(
                        s,
                        "<td>{:.4}</td><td>{:.4}</td><td>{}</td><td>{:.4}</td><td>{:.4}</td>",
                        b.largest_step, b.truth_largest_step, b.visible_steps, b.profile_error, b.noise
                    );
                }
                None => s.push_str("<td colspan=\"5\">no contrast</td>"),
            }
            let _ = write!(s, "<td>{:.1}</td><td>{:.1}</td></tr>", r.shadow_ms, r.frame_ms);
        }
        s.push_str("</table>");
        // one plot per technique: the truth and each light-set setting
        let mut techniques: Vec<&str> = self.rows.iter().map(|r| r.technique.as_str()).collect();
        techniques.dedup();
        for technique in techniques {
            let mut series = vec![("truth (the map)".to_string(), self.case.profile(None))];
            for r in self.rows.iter().filter(|r| r.technique == technique) {
                let label =
                    if r.interleave.sets > 1 { format!("{} sets", r.interleave.name()) } else { "one set".into() };
                series.push((label, self.case.profile(Some(&r.image))));
            }
            let title = format!("{technique}: luminance across the wall's shadow (mean down each column)");
            s.push_str(&trade::report::profile_svg(&title, &series, "luminance").map_err(|e| e.to_string())?);
        }
        s.push_str("<div class=\"grid\">");
        let tonemap = Tonemap::auto(self.rows.first().map_or(&[][..], |r| &r.image[..]));
        for r in &self.rows {
            let name = format!("banding_{}_{}", r.technique, r.interleave.name().replace(" x ", "x"));
            let bytes: Vec<u8> = r.image.iter().flat_map(|p| tonemap.apply(*p)).collect();
            let img = png(&name, self.size, &bytes)?;
            let _ = write!(s, "<figure>{img}<figcaption>{name}</figcaption></figure>");
        }
        s.push_str("</div>");
        Ok(s)
    }
}

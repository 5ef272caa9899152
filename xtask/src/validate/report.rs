//! The validate report: a self-contained HTML page with every image, error map, table and the
//! adapter and driver used.

use super::{Plan, Row};
use envmap_sphere::Tonemap;
use glam::Vec3;
use gpu::Gpu;
use ref_tracer::metrics::FlipTonemap;
use shadowmap_paraboloid::Technique;
use std::fmt::Write as _;
use std::path::Path;
use trade::stages::{MaskImages, MaskRow, SizeRow};

pub(super) struct Report<'a> {
    pub(super) gpu: &'a Gpu,
    pub(super) plan: &'a Plan,
    pub(super) map_name: &'a str,
    pub(super) scene: &'a str,
    pub(super) rows: &'a [Row],
    pub(super) masks: &'a [MaskRow],
    pub(super) mask_images: &'a MaskImages,
    pub(super) sizes: &'a [SizeRow],
    pub(super) clock: gpu::Clock,
    pub(super) tm: &'a FlipTonemap,
    pub(super) size: (u32, u32),
    pub(super) failures: &'a [String],
    pub(super) checked: usize,
    pub(super) lights: usize,
    pub(super) extract_ms: f64,
    pub(super) method: &'a str,
    pub(super) compositing: &'a super::composite_stage::Compositing,
    /// The banding stage (`--interleaved`).
    pub(super) banding: Option<&'a super::banding_stage::BandingStage>,
}

/// Relative luminance error as an 8-bit heat map (black 0, red 25 %, yellow 50 %, white ≥ 75 %).
pub(super) fn error_map(reference: &[Vec3], test: &[Vec3]) -> Vec<u8> {
    let y = envmap_sphere::luminance;
    let mean = reference.iter().map(|c| y(*c)).sum::<f32>() / reference.len().max(1) as f32;
    reference
        .iter()
        .zip(test)
        .flat_map(|(r, t)| {
            let e = (y(*t) - y(*r)).abs() / (y(*r) + 0.05 * mean).max(1e-12);
            let c = |x: f32| (x.clamp(0.0, 1.0) * 255.0) as u8;
            [c(e * 4.0), c(e * 4.0 - 1.0), c(e * 4.0 - 2.0)]
        })
        .collect()
}

fn mask_bytes(mask: &[f32]) -> Vec<u8> {
    mask.iter().flat_map(|m| [(m.clamp(0.0, 1.0) * 255.0) as u8; 3]).collect()
}

fn truth_diff_bytes(mask: &[f32], truth: &[Option<bool>]) -> Vec<u8> {
    mask.iter()
        .zip(truth)
        .flat_map(|(m, t)| match t {
            None => [40, 40, 60],
            Some(t) if (*m > 0.5) == *t => {
                if *t {
                    [200, 200, 200]
                } else {
                    [30, 30, 30]
                }
            }
            Some(true) => [230, 40, 40],
            Some(false) => [40, 120, 255],
        })
        .collect()
}

impl Report<'_> {
    /// Writes `name.png` into `dir` and returns an `<img>` embedding the same bytes.
    fn png(&self, dir: &Path, name: &str, (w, h): (u32, u32), bytes: &[u8]) -> Result<String, String> {
        let png = envmap_sphere::io::encode_png_srgb8(w, h, bytes).map_err(|e| format!("{name}.png: {e}"))?;
        let path = dir.join(format!("{name}.png"));
        std::fs::write(&path, &png).map_err(|e| format!("{}: {e}", path.display()))?;
        Ok(format!("<img alt=\"{name}\" src=\"data:image/png;base64,{}\">", base64(&png)))
    }

    pub(super) fn html(&self, dir: &Path) -> Result<String, String> {
        let mut s = String::new();
        let tonemap: Tonemap = self.tm.tonemap;
        let _ = write!(
            s,
            "<!doctype html><html><head><meta charset=\"utf-8\"><title>envshadow validate</title><style>\
             body{{font-family:sans-serif;margin:2em;max-width:1400px}} table{{border-collapse:collapse}} \
             td,th{{border:1px solid #bbb;padding:4px 8px;text-align:right}} th{{background:#eee}} \
             td:first-child,th:first-child{{text-align:left}} img{{max-width:100%}} .fail{{color:#b00;font-weight:bold}} \
             .grid{{display:grid;grid-template-columns:repeat(3,1fr);gap:8px}} figure{{margin:0}}</style></head><body>"
        );
        let _ = write!(
            s,
            "<h1>envshadow validate</h1><p>Map <b>{}</b>, scene <b>{}</b>. {}.</p>",
            self.map_name,
            self.scene,
            self.plan.describe()
        );
        let _ = write!(
            s,
            "<p>GPU adapter: <b>{}</b>. Timings of shadow maps: {}.</p>",
            html_escape(&self.gpu.describe()),
            self.clock.name()
        );
        let _ = write!(
            s,
            "<p>{} found {} lights in {:.1} ms. {}</p>",
            html_escape(self.method),
            self.lights,
            self.extract_ms,
            html_escape(&self.tm.describe())
        );
        if self.failures.is_empty() {
            let _ = write!(s, "<p>Thresholds (validate/thresholds.json): {} checked, all met.</p>", self.checked);
        } else {
            let _ = write!(
                s,
                "<p class=\"fail\">Thresholds exceeded:<br>{}</p>",
                self.failures.iter().map(|f| html_escape(f)).collect::<Vec<_>>().join("<br>")
            );
        }
        let _ = write!(
            s,
            "<h2>Environment lighting: techniques against the reference</h2><table><tr><th>technique</th><th>what</th><th>RMSE</th><th>FLIP</th><th>RMSE vs ray-traced lights</th><th>time (s)</th></tr>"
        );
        let fmt = |v: Option<f64>| v.map_or_else(|| "—".to_string(), |v| format!("{v:.4}"));
        for r in self.rows {
            let _ = write!(
                s,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                r.name,
                html_escape(&r.what),
                fmt(r.rmse),
                fmt(r.flip),
                fmt(r.rmse_vs_lights),
                if r.seconds > 0.0 { format!("{:.2}", r.seconds) } else { "—".into() }
            );
        }
        s.push_str("</table>");
        let points = super::gpu_points(self.rows);
        if !points.is_empty() {
            s.push_str("<h3>This run's trade</h3><p>The GPU rows' error against their time (wall time on this adapter, end to end, readbacks included); the Pareto front in red. <code>cargo xtask trade</code> measures every knob this way, per frame; <code>validate --budget-ms MS</code> picks from these rows.</p>");
            s.push_str(
                &trade::report::plot_svg("validate: GPU rows", &points, trade::Family::Env.error_axis())
                    .map_err(|e| e.to_string())?,
            );
        }
        s.push_str("<p>Images (same tone mapping as FLIP) and relative luminance error against the reference (black 0, red 25 %, yellow 50 %, white ≥ 75 %).</p><div class=\"grid\">");
        let reference = &self.rows[0].image;
        for r in self.rows {
            let bytes: Vec<u8> = r.image.iter().flat_map(|p| tonemap.apply(*p)).collect();
            let img = self.png(dir, &r.name, self.size, &bytes)?;
            let err = if r.rmse.is_some() {
                self.png(dir, &format!("{}_error", r.name), self.size, &error_map(reference, &r.image))?
            } else {
                String::new()
            };
            let _ = write!(
                s,
                "<figure>{img}<figcaption>{}</figcaption></figure><figure>{err}</figure><figure></figure>",
                r.name
            );
        }
        s.push_str("</div>");
        let _ = write!(
            s,
            "<h2>Point light in <code>room</code>: shadow maps against ray-traced visibility</h2><p>The fraction of visible pixels whose shadow-map test (1-texel bias, no PCF) disagrees with a ray traced from the same G-buffer point to the light; generation time of all passes of the map. Pairs of rows have equal texel counts (2 p² = 6 c²).</p><table><tr><th>map</th><th>texels</th><th>triangles drawn</th><th>pixels that disagree</th><th>generation (ms)</th><th>time / cube</th></tr>"
        );
        for m in self.masks {
            let cube = self
                .masks
                .iter()
                .find(|c| c.technique == Technique::Cube && c.texels.abs_diff(m.texels) * 50 < m.texels);
            let ratio = cube.map_or_else(|| "—".to_string(), |c| format!("{:.2}×", m.gpu_ms / c.gpu_ms));
            let _ = write!(
                s,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{:.3} %</td><td>{:.2}</td><td>{ratio}</td></tr>",
                m.name,
                m.texels,
                m.triangles,
                m.disagreement * 100.0,
                m.gpu_ms
            );
        }
        s.push_str("</table><h3>Error against triangle size</h3><p>Dual paraboloid 1024², clip distances: triangles bisected until no edge spans more than the angle from the light (the paper's caveat: rasterization interpolates the non-linear mapping linearly).</p><table><tr><th>widest edge from the light</th><th>triangles</th><th>pixels that disagree</th></tr>");
        for r in self.sizes {
            let _ = write!(
                s,
                "<tr><td>{:.3} rad</td><td>{}</td><td>{:.3} %</td></tr>",
                r.widest,
                r.triangles,
                r.disagreement * 100.0
            );
        }
        s.push_str("</table><p>Masks: dual paraboloid 1024² (clip distances, subdivided), cube 592², and where each disagrees with the ray-traced truth (red: lit but should be shadowed, blue: shadowed but lit).</p><div class=\"grid\">");
        let (para, cube, truth, size) = self.mask_images;
        for (name, bytes) in [
            ("room_paraboloid_1024", mask_bytes(para)),
            ("room_cube_592", mask_bytes(cube)),
            ("room_paraboloid_1024_vs_ray_traced", truth_diff_bytes(para, truth)),
        ] {
            let img = self.png(dir, name, *size, &bytes)?;
            let _ = write!(s, "<figure>{img}<figcaption>{name}</figcaption></figure>");
        }
        s.push_str("</div>");
        s.push_str(&self.compositing.html(&|name, size, bytes| self.png(dir, name, size, bytes))?);
        if let Some(banding) = self.banding {
            s.push_str(&banding.html(&|name, size, bytes| self.png(dir, name, size, bytes))?);
        }
        s.push_str("</body></html>\n");
        Ok(s)
    }
}

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

/// Standard base64 with padding (RFC 4648), for images embedded in the report.
fn base64(data: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(data.len().div_ceil(3) * 4);
    for chunk in data.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[((n >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::base64;

    #[test]
    fn base64_matches_rfc_4648_vectors() {
        for (input, want) in [("", ""), ("f", "Zg=="), ("fo", "Zm8="), ("foo", "Zm9v"), ("foobar", "Zm9vYmFy")] {
            assert_eq!(base64(input.as_bytes()), want);
        }
    }
}

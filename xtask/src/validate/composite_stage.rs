//! Validate's compositing stage (paper 003): a sphere composited into `ar_ground`'s photograph
//! on the GPU with 1, 10, 20, 50 and all passes, HDR and LDR, against the path-traced truth and
//! Debevec's offline differential rendering; Figure 3's error of the two-set split; the report's
//! section.

use std::fmt::Write as _;

use crate::common::WritePng;
use differential_composite::gpu::{GpuCompositor, GpuSettings};
use differential_composite::{CodeError, Mode, code_error};
use glam::Vec3;
use gpu::Gpu;
use real_scene::RealScene;
use trade::composite_rows::{Row, figure3_datasets, rows};
use trade::{PhotoSettings, Session, SessionSettings};

/// Where the sphere sits, from the floor's centre: on the ground in front of the boxes.
const AT: Vec3 = Vec3::new(0.0, 0.3, 1.0);

/// The stage's results.
pub(super) struct Compositing {
    pub(super) size: (u32, u32),
    pub(super) spp: u32,
    pub(super) photo: Vec<[u8; 3]>,
    pub(super) truth: Vec<[u8; 3]>,
    pub(super) debevec: Vec<[u8; 3]>,
    pub(super) debevec_error: CodeError,
    pub(super) rows: Vec<Row>,
    /// (split of the first set, RMS error in codes per P occluded)
    pub(super) figure3: Vec<(f64, Vec<(usize, f64)>)>,
    pub(super) figure3_vertices: usize,
}

/// Runs the stage: `quick` at 160 x 120 and 8 spp, else 320 x 240 and 16 spp.
pub(super) fn run(gpu: &Gpu, quick: bool) -> Result<Compositing, String> {
    let (size, spp) = if quick { ((160, 120), 8) } else { ((320, 240), 16) };
    let scene = RealScene::builtin("ar_ground").map_err(|e| e.to_string())?;
    let (map, lights) = crate::common::environment(&scene)?;
    let settings = SessionSettings {
        size: Some(size),
        photo: PhotoSettings { spp, ..SessionSettings::default().photo },
        ..SessionSettings::default()
    };
    let e = |e: differential_composite::CompositeError| e.to_string();
    let session = Session::new("ar_ground", map, lights, &settings).map_err(e)?;
    let object = session.object("sphere", AT).map_err(e)?;
    let truth = session.truth(&object).map_err(e)?;
    let debevec = session.debevec(&object).map_err(e)?;
    let c = &session.compositor;
    let gc = GpuCompositor::new(gpu, c).map_err(|e| e.to_string())?;
    let table = rows(
        gpu,
        &gc,
        &session.compositor,
        &object,
        &truth,
        &[1, 10, 20, 50, 0],
        &[Mode::Hdr, Mode::Ldr],
        &GpuSettings::default(),
        3,
    )
    .map_err(|e| e.to_string())?;
    let frame = c.frame(&object, 0);
    let data = figure3_datasets(&session, &frame, 4, 16);
    let figure3 = [0.5, 0.25]
        .into_iter()
        .map(|share| (share, differential_composite::ldr::figure3(&data, &c.response, share, 2000, 1)))
        .collect();
    Ok(Compositing {
        size,
        spp,
        debevec_error: code_error(&debevec, &truth, &c.photo_ldr),
        photo: c.photo_ldr.clone(),
        truth,
        debevec,
        rows: table,
        figure3,
        figure3_vertices: data.len(),
    })
}

impl Compositing {
    /// The measured keys: `<key>:composite_<passes>_<hdr|ldr>.mae_codes`.
    pub(super) fn measured(&self, quick: bool) -> Vec<(String, f64)> {
        let key = format!("ar_ground_composite{}", if quick { "/quick" } else { "" });
        self.rows
            .iter()
            .map(|r| (format!("{key}:{}.mae_codes", row_name(r)), r.error.mae_changed))
            .chain(std::iter::once((format!("{key}:debevec.mae_codes"), self.debevec_error.mae_changed)))
            .collect()
    }

    /// The report's section; `png` writes an image and returns its `<img>`.
    pub(super) fn html(&self, png: &WritePng<'_>) -> Result<String, String> {
        let mut s = String::new();
        let _ = write!(
            s,
            "<h2>Compositing (paper 003): a sphere into <code>ar_ground</code>'s photograph</h2><p>{}x{}, photograph, truth and Debevec's renders path traced at {} spp; the sphere at {:?} m from the floor's centre. Errors in 8-bit codes against the truth (the real scene path traced with the sphere) over the {} pixels the sphere changed. Debevec's offline differential rendering with the same model: MAE {:.2}, RMSE {:.2}. Times per frame on this adapter, the median of 3: the CPU's work and recording, then each GPU stage by {}.</p>",
            self.size.0,
            self.size.1,
            self.spp,
            AT.to_array(),
            self.debevec_error.changed,
            self.debevec_error.mae_changed,
            self.debevec_error.rmse_changed,
            self.rows.first().map_or("—", |r| r.times.clock.name())
        );
        s.push_str("<table><tr><th>passes</th><th>representatives</th><th>mode</th><th>MAE (codes)</th><th>RMSE (codes)</th><th>MAE / Debevec's</th><th>ms per frame</th><th>CPU</th><th>G-buffer</th><th>maps</th><th>masks</th><th>resolve</th></tr>");
        for r in &self.rows {
            let _ = write!(
                s,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{:.2}</td><td>{:.2}</td><td>{:.2}</td>",
                r.passes_label(),
                r.reps,
                r.mode_label(),
                r.error.mae_changed,
                r.error.rmse_changed,
                r.error.mae_changed / self.debevec_error.mae_changed.max(1e-9),
            );
            for t in r.times_ms() {
                let _ = write!(s, "<td>{t:.2}</td>");
            }
            s.push_str("</tr>");
        }
        s.push_str("</table><div class=\"grid\">");
        let flat = |img: &[[u8; 3]]| img.iter().flatten().copied().collect::<Vec<u8>>();
        let composite = self.rows.iter().find(|r| r.passes == 50 && r.mode == Mode::Hdr).unwrap_or(&self.rows[0]);
        let error = flat(&differential_composite::metrics::error_image(&composite.image, &self.truth));
        for (name, bytes) in [
            ("composite_photo", flat(&self.photo)),
            ("composite_truth", flat(&self.truth)),
            ("composite_gpu_50_hdr", flat(&composite.image)),
            ("composite_debevec", flat(&self.debevec)),
            ("composite_gpu_50_hdr_error_x8", error),
        ] {
            let img = png(name, self.size, &bytes)?;
            let _ = write!(s, "<figure>{img}<figcaption>{name}</figcaption></figure>");
        }
        let _ = write!(
            s,
            "</div><h3>Figure 3: the two-set split under random occlusion</h3><p>{} receiver vertices near the sphere with their 16 largest occluded transfers; RMS error in codes of the LDR subtraction when P random sources are occluded (2,000 trials each).</p><table><tr><th>split</th>",
            self.figure3_vertices
        );
        if let Some((_, curve)) = self.figure3.first() {
            for (p, _) in curve {
                let _ = write!(s, "<th>P = {p}</th>");
            }
        }
        s.push_str("</tr>");
        for (share, curve) in &self.figure3 {
            let _ = write!(s, "<tr><td>{:.0} / {:.0}</td>", share * 100.0, (1.0 - share) * 100.0);
            for (_, e) in curve {
                let _ = write!(s, "<td>{e:.2}</td>");
            }
            s.push_str("</tr>");
        }
        s.push_str("</table>");
        Ok(s)
    }
}

fn row_name(r: &Row) -> String {
    format!("composite_{}_{}", r.passes_label(), r.mode_label().to_lowercase())
}

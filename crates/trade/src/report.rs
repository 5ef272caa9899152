//! The HTML report: error against ms per frame, one plot per scene and map and one over all,
//! the Pareto front drawn and its settings named, and the tables behind them.

use crate::TradeError;
use crate::front::{Point, front, overall};
use crate::setting::Family;
use crate::table::Run;
use plotters::coord::combinators::BindKeyPoints;
use plotters::prelude::*;
use std::fmt::Write as _;

/// An SVG plot of error (`error_axis` names it) against ms (log time, linear error) with the
/// front drawn and its points named.
///
/// # Errors
/// [`TradeError::Plot`] when plotters fails (e.g. no finite point).
pub fn plot_svg(title: &str, points: &[Point], error_axis: &str) -> Result<String, TradeError> {
    let finite: Vec<&Point> =
        points.iter().filter(|p| p.ms > 0.0 && p.rmse > 0.0 && p.ms.is_finite() && p.rmse.is_finite()).collect();
    let plot_err = |e: &dyn std::fmt::Display| TradeError::Plot(format!("{title}: {e}"));
    if finite.is_empty() {
        return Err(plot_err(&"no point with a positive, finite time and error"));
    }
    let range = |f: &dyn Fn(&Point) -> f64| {
        let lo = finite.iter().map(|p| f(p)).fold(f64::INFINITY, f64::min);
        let hi = finite.iter().map(|p| f(p)).fold(0.0, f64::max);
        (lo / 1.5)..(hi * 1.5)
    };
    let xr = range(&|p| p.ms);
    // linear in error (a log axis over one decade gets one label), from zero
    let yr = 0.0..finite.iter().map(|p| p.rmse).fold(0.0, f64::max) * 1.15;
    let f = front(points);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (760, 480)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| plot_err(&e))?;
        let mut chart = builder(&root, title)
            .build_cartesian_2d(xr.clone().log_scale().with_key_points(key_points(&xr)), yr)
            .map_err(|e| plot_err(&e))?;
        chart
            .configure_mesh()
            .x_desc("ms per frame")
            .y_desc(error_axis)
            .x_labels(8)
            .y_labels(8)
            .max_light_lines(2)
            .x_label_formatter(&|x| short_number(*x))
            .y_label_formatter(&|y| short_number(*y))
            .draw()
            .map_err(|e| plot_err(&e))?;
        chart
            .draw_series(finite.iter().map(|p| Circle::new((p.ms, p.rmse), 4, RGBColor(120, 120, 120).filled())))
            .map_err(|e| plot_err(&e))?
            .label("setting")
            .legend(|(x, y)| Circle::new((x, y), 4, RGBColor(120, 120, 120).filled()));
        // the front as a staircase: a setting is worth its time until the next one is reached
        let mut steps = Vec::new();
        for (k, p) in f.iter().enumerate() {
            steps.push((p.ms, p.rmse));
            if let Some(next) = f.get(k + 1) {
                steps.push((next.ms, p.rmse));
            }
        }
        chart
            .draw_series(LineSeries::new(steps, RED.stroke_width(2)))
            .map_err(|e| plot_err(&e))?
            .label("Pareto front")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], RED.stroke_width(2)));
        // labels alternate above and below their points: neighbours on the front sit close
        chart
            .draw_series(f.iter().enumerate().map(|(k, p)| {
                EmptyElement::at((p.ms, p.rmse))
                    + Circle::new((0, 0), 5, RED.filled())
                    + Text::new(label(&p.setting), (6, if k % 2 == 0 { -14 } else { 4 }), ("sans-serif", 11))
            }))
            .map_err(|e| plot_err(&e))?;
        chart
            .configure_series_labels()
            .border_style(BLACK)
            .background_style(WHITE.mix(0.8))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| plot_err(&e))?;
        root.present().map_err(|e| plot_err(&e))?;
    }
    Ok(svg)
}

/// Tick values 1, 2, 5 x 10^n within `range`, or every 1..9 x 10^n where that gives fewer than
/// three (a log axis over less than a decade otherwise gets one label).
/// An SVG line plot of profiles across an image (`series`: name and (column, value) points;
/// the first drawn black and thick, as the truth), `y_axis` naming the values.
///
/// # Errors
/// [`TradeError::Plot`] when plotters fails or no series has a finite point.
pub fn profile_svg(title: &str, series: &[(String, Vec<(f64, f64)>)], y_axis: &str) -> Result<String, TradeError> {
    let plot_err = |e: &dyn std::fmt::Display| TradeError::Plot(format!("{title}: {e}"));
    let points = || series.iter().flat_map(|s| s.1.iter()).filter(|p| p.0.is_finite() && p.1.is_finite());
    let (x0, x1, y1) =
        points().fold((f64::INFINITY, f64::NEG_INFINITY, 0.0f64), |(a, b, c), p| (a.min(p.0), b.max(p.0), c.max(p.1)));
    if x0 > x1 {
        return Err(plot_err(&"no finite point"));
    }
    let colours = [RGBColor(214, 39, 40), RGBColor(31, 119, 180), RGBColor(44, 160, 44), RGBColor(255, 127, 14)];
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (760, 400)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| plot_err(&e))?;
        let mut chart = builder(&root, title)
            .build_cartesian_2d(x0..x1.max(x0 + 1.0), 0.0..(y1 * 1.1).max(1e-12))
            .map_err(|e| plot_err(&e))?;
        chart
            .configure_mesh()
            .x_desc("column")
            .y_desc(y_axis)
            .max_light_lines(2)
            .y_label_formatter(&|y| short_number(*y))
            .draw()
            .map_err(|e| plot_err(&e))?;
        for (k, (name, pts)) in series.iter().enumerate() {
            let style = if k == 0 { BLACK.stroke_width(3) } else { colours[(k - 1) % colours.len()].stroke_width(1) };
            let finite: Vec<(f64, f64)> = pts.iter().copied().filter(|p| p.0.is_finite() && p.1.is_finite()).collect();
            chart
                .draw_series(LineSeries::new(finite, style))
                .map_err(|e| plot_err(&e))?
                .label(name.as_str())
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 16, y)], style));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::LowerRight)
            .draw()
            .map_err(|e| plot_err(&e))?;
        root.present().map_err(|e| plot_err(&e))?;
    }
    Ok(svg)
}

/// The plots' common frame: title, margin, axis label areas.
fn builder<'a, 'b, DB: DrawingBackend>(
    root: &'a DrawingArea<DB, plotters::coord::Shift>,
    title: &'b str,
) -> ChartBuilder<'a, 'b, DB> {
    let mut b = ChartBuilder::on(root);
    b.caption(title, ("sans-serif", 18)).margin(12).x_label_area_size(40).y_label_area_size(64);
    b
}

fn key_points(range: &std::ops::Range<f64>) -> Vec<f64> {
    let ticks = |mantissas: &[f64]| {
        let (lo, hi) = (range.start.max(f64::MIN_POSITIVE), range.end);
        let mut out = Vec::new();
        let mut decade = 10f64.powf(lo.log10().floor());
        while decade <= hi && out.len() < 64 {
            for m in mantissas {
                let v = decade * m;
                if v >= lo && v <= hi {
                    out.push(v);
                }
            }
            decade *= 10.0;
        }
        out
    };
    let coarse = ticks(&[1.0, 2.0, 5.0]);
    if coarse.len() >= 3 { coarse } else { ticks(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]) }
}

/// An axis label with about two significant digits: 1200, 35, 4.5, 0.012.
fn short_number(x: f64) -> String {
    let digits = if x <= 0.0 || !x.is_finite() { 0 } else { (1.0 - x.log10().floor()).max(0.0) as usize };
    format!("{x:.digits$}")
}

/// A setting's name for a plot label: the best method's name left out (the report says so).
fn label(setting: &str) -> String {
    setting.strip_prefix(&format!("{}/", light_extract::DEFAULT_METHOD)).unwrap_or(setting).to_string()
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

/// What each family's truth is, for the report.
fn truth_text(family: Family, c: &crate::RunConfig) -> String {
    match family {
        Family::Env => format!(
            "Truth: ref-tracer <code>env-direct</code> at {} spp (its noise is two truths of independent seeds apart, / &radic;2). GPU frames on a rotated grid of {} samples per pixel.",
            c.truth_spp,
            c.supersample * c.supersample + 1
        ),
        Family::Point => format!(
            "Truth: the same frame (G-buffer on the rotated grid of {} samples per pixel, shading) with the visibility of every point light ray traced from every G-buffer point: the error is the shadow maps' alone, and the truth has no noise.",
            c.supersample * c.supersample + 1
        ),
        Family::Composite => format!(
            "A sphere composited into the photograph of a built-in real scene (path traced at {} spp, an exact reconstruction, the shaft hierarchy pruning at 2 %). Truth: the real scene path traced with the sphere (its noise: a second truth of another seed, / &radic;2; the composite starts from the photograph, which shares the first truth's seed, so its error can lie below that). Errors in 8-bit codes over the pixels the sphere changed; FLIP on the 8-bit images. Times include the CPU's traversal and transfers and the 8-bit image's readback.",
            c.photo_spp
        ),
    }
}

/// The report of `run`, with the chooser's picks for `budgets` (ms) within each family over
/// all its scenes and maps.
///
/// # Errors
/// A plot that cannot be drawn.
pub fn html(run: &Run, budgets: &[f64]) -> Result<String, TradeError> {
    let c = &run.config;
    let mut h = String::from(
        "<!doctype html><html><head><meta charset=\"utf-8\"><title>envshadow: the trade</title><style>body{font-family:sans-serif;max-width:1100px;margin:2em auto;color:#222}table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;padding:3px 8px;font-size:13px}th{background:#f2f2f2}td.n{text-align:right}tr.front{background:#fff0f0}</style></head><body>",
    );
    let _ = write!(
        h,
        "<h1>The trade: time against error</h1><p>{} x {}; times are the median of {} frames (everything the frame waits for) on <b>{}</b>. Preset: {}. Shards: {}. Plot labels leave out the method when it is the best one, <code>{}</code>. Each family has its own truth, so its own fronts and choices.</p><ul>",
        c.size.0,
        c.size.1,
        c.repeats,
        escape(&c.adapter),
        escape(&c.preset),
        escape(&run.shards.join(", ")),
        light_extract::DEFAULT_METHOD
    );
    let families: Vec<Family> = Family::ALL.into_iter().filter(|f| run.rows.iter().any(|r| r.family() == *f)).collect();
    for f in &families {
        let _ = write!(h, "<li><a href=\"#{}\">{}</a></li>", f.name(), f.title());
    }
    h.push_str("</ul>");
    for family in families {
        let _ = write!(h, "<h2 id=\"{}\">{}</h2><p>{}</p>", family.name(), family.title(), truth_text(family, c));
        let axis = family.error_axis();
        let all = overall(&run.rows, family);
        if !all.is_empty() {
            h.push_str("<h3>Over all its scenes and maps</h3><p>Mean ms and mean error of each setting measured on every scene and map of the family.</p>");
            h.push_str(&plot_svg(&format!("{}: all scenes and maps", family.name()), &all, axis)?);
            h.push_str("<h4>The front</h4><table><tr><th>setting</th><th>ms</th><th>RMSE</th><th>FLIP</th></tr>");
            for p in front(&all) {
                let _ = write!(
                    h,
                    "<tr><td>{}</td><td class=n>{:.3}</td><td class=n>{:.5}</td><td class=n>{:.4}</td></tr>",
                    escape(&p.setting),
                    p.ms,
                    p.rmse,
                    p.flip
                );
            }
            h.push_str("</table><h4>The chooser</h4><table><tr><th>budget</th><th>choice</th></tr>");
            for b in budgets {
                let cell = match crate::front::choose(&all, *b) {
                    Ok(p) => format!("{} ({:.3} ms, RMSE {:.5})", escape(&p.setting), p.ms, p.rmse),
                    Err(e) => escape(&e.to_string()),
                };
                let _ = write!(h, "<tr><td class=n>{b} ms</td><td>{cell}</td></tr>");
            }
            h.push_str("</table>");
        }
        let mut cases: Vec<(&str, &str)> =
            run.rows.iter().filter(|r| r.family() == family).map(|r| (r.scene.as_str(), r.map.as_str())).collect();
        cases.dedup();
        for (scene, map) in cases {
            case_section(&mut h, run, family, scene, map)?;
        }
    }
    h.push_str("</body></html>\n");
    Ok(h)
}

/// One scene and map of a family: its plot and table.
fn case_section(h: &mut String, run: &Run, family: Family, scene: &str, map: &str) -> Result<(), TradeError> {
    let rows: Vec<_> = run.rows.iter().filter(|r| r.family() == family && r.scene == scene && r.map == map).collect();
    let points: Vec<Point> =
        rows.iter().map(|r| Point { setting: r.setting.clone(), ms: r.ms, rmse: r.rmse, flip: r.flip }).collect();
    let noise = rows.first().map_or(0.0, |r| r.truth_noise);
    let under = if map == "-" { String::new() } else { format!(" under {}", escape(map)) };
    let _ = write!(h, "<h3>{}{under}</h3><p>The truth's own noise: RMSE {noise:.5}.</p>", escape(scene));
    let title = if map == "-" { scene.to_string() } else { format!("{scene} / {map}") };
    h.push_str(&plot_svg(&title, &points, family.error_axis())?);
    let passes = if family == Family::Composite { "passes" } else { "lights shadowed" };
    let _ = write!(
        h,
        "<table><tr><th>setting</th><th>ms</th><th>shadow passes ms</th><th>RMSE</th><th>FLIP</th><th>{passes}</th><th>skipped</th><th>culled</th><th>extraction ms (CPU)</th></tr>"
    );
    let mut sorted = rows.clone();
    sorted.sort_by(|a, b| a.ms.total_cmp(&b.ms));
    for r in sorted {
        let skipped: Vec<String> = r.skipped.iter().map(|(why, n)| format!("{n}: {why}")).collect();
        let culled: Vec<String> = r.culled.iter().map(|(what, n)| format!("{n} {what}")).collect();
        let _ = write!(
            h,
            "<tr{}><td>{}</td><td class=n>{:.3}</td><td class=n title=\"{}\">{:.3}</td><td class=n>{:.5}</td><td class=n>{:.4}</td><td class=n>{}</td><td>{}</td><td>{}</td><td class=n>{:.1}</td></tr>",
            if r.pareto { " class=front" } else { "" },
            escape(&r.setting),
            r.ms,
            escape(&r.shadow_clock),
            r.shadow_ms,
            r.rmse,
            r.flip,
            r.shadowed,
            escape(&skipped.join("; ")),
            escape(&culled.join("; ")),
            r.extract_ms
        );
    }
    h.push_str("</table>");
    Ok(())
}

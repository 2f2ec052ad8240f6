//! The thermal stage's outputs: the model file (TOML), the `--json` of
//! `thermal evaluate` and `thermal apply`, their terminal reports, the
//! plots of drift and temperatures against time, the report's thermal
//! section and the web app's thermal page, and the share of a re-test's
//! drift the logged temperatures explain.

use serde::Serialize;

use crate::diagnose::thermal::{RecordedChange, ThermalShare};
use crate::report::chart::{Chart, Mark, Rgb, Series, chart};
use crate::report::format::esc;
use crate::report::plot::{PlotError, PlotFormat};
use crate::thermal::{
    Application, Iso230_3, Study, TestType, ThermalLog, ThermalModel, Validation,
};

/// The model file: `[fit]` (what it was fitted on) and one `[[term]]` per
/// lagged sensor; `thermal::ThermalModel::from_toml` reads it back.
#[derive(Serialize)]
struct ModelFile<'a> {
    fit: FitFile<'a>,
    term: Vec<TermFile<'a>>,
}

#[derive(Serialize)]
struct FitFile<'a> {
    drift: &'a str,
    first_row: usize,
    last_row: usize,
    from_s: f64,
    to_s: f64,
    candidates: &'a [String],
    #[serde(skip_serializing_if = "Option::is_none")]
    reference: Option<&'a str>,
    blocks: usize,
    validation: &'static str,
    cv_rms_um: f64,
    fit_rms_um: f64,
}

#[derive(Serialize)]
struct TermFile<'a> {
    sensor: &'a str,
    tau_s: f64,
    coefficient_um_per_k: f64,
    reference_c: f64,
}

/// The model as its TOML file, with a comment saying what it computes.
pub fn model_toml(model: &ThermalModel) -> String {
    let f = &model.fit;
    let file = ModelFile {
        fit: FitFile {
            drift: &f.drift,
            first_row: f.first_row,
            last_row: f.last_row,
            from_s: f.from_s,
            to_s: f.to_s,
            candidates: &f.candidates,
            reference: f.reference.as_deref(),
            blocks: f.blocks,
            validation: f.validation.name(),
            cv_rms_um: f.cv_rms_um,
            fit_rms_um: f.fit_rms_um,
        },
        term: model
            .terms
            .iter()
            .map(|t| TermFile {
                sensor: &t.sensor,
                tau_s: t.tau_s,
                coefficient_um_per_k: t.coefficient_um_per_k,
                reference_c: t.reference_c,
            })
            .collect(),
    };
    let body = toml::to_string(&file).unwrap_or_default();
    format!(
        "# axcomp thermal model: drift_um(t) = sum over terms of\n\
         #   coefficient_um_per_k * (lag(sensor, tau_s)(t) - reference_c),\n\
         # each lag a first-order low-pass started at the log's first row.\n\
         # cv_rms_um is the prediction's standard uncertainty in the fit rows' conditions (time-blocked cross-validation); beyond them it can be larger.\n{body}"
    )
}

/// rms and largest size of a set of values, µm.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Spread {
    /// Root mean square, µm.
    pub rms_um: f64,
    /// Largest absolute value, µm.
    pub max_um: f64,
    /// How many rows.
    pub rows: usize,
}

impl Spread {
    /// Of `values` (none: zeros).
    pub fn of(values: &[f64]) -> Spread {
        let rows = values.len();
        let sum: f64 = values.iter().map(|v| v * v).sum();
        Spread {
            rms_um: if rows == 0 {
                0.0
            } else {
                (sum / rows as f64).sqrt()
            },
            max_um: values.iter().fold(0.0, |m: f64, v| m.max(v.abs())),
            rows,
        }
    }
}

/// Before (the drift) and after (the residual) over a set of rows.
#[derive(Serialize)]
pub struct BeforeAfter {
    /// The measured drift from the first row.
    pub before: Spread,
    /// Measured minus predicted.
    pub after: Spread,
}

/// `thermal apply --json`.
#[derive(Serialize)]
pub struct ApplyJson {
    /// The time of each row, s from the first.
    pub time_s: Vec<f64>,
    /// The model's drift at each row, µm.
    pub predicted_um: Vec<f64>,
    /// Measured minus predicted, where the log has the drift column.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub residual_um: Option<Vec<f64>>,
    /// Over every row.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub all_rows: Option<BeforeAfter>,
    /// Over the rows outside the model's fitted rows (the held-out rows,
    /// when the log is the one it was fitted on).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub outside_fit_rows: Option<BeforeAfter>,
}

/// The JSON of a model run over a log.
pub fn apply_json(model: &ThermalModel, log: &ThermalLog, applied: &Application) -> ApplyJson {
    let residual = applied.residual_um();
    let figures = |keep: &dyn Fn(usize) -> bool| {
        let measured = applied.measured_um.as_ref()?;
        let residual = residual.as_ref()?;
        let pick = |v: &[f64]| -> Vec<f64> {
            v.iter()
                .enumerate()
                .filter(|(i, _)| keep(*i))
                .map(|(_, x)| *x)
                .collect()
        };
        Some(BeforeAfter {
            before: Spread::of(&pick(measured)),
            after: Spread::of(&pick(residual)),
        })
    };
    let fitted = model.fit.first_row - 1..model.fit.last_row;
    let outside = figures(&|i| !fitted.contains(&i)).filter(|f| f.after.rows > 0);
    ApplyJson {
        time_s: log.times_s.clone(),
        predicted_um: applied.predicted_um.clone(),
        all_rows: figures(&|_| true),
        outside_fit_rows: outside,
        residual_um: residual,
    }
}

/// The apply report for the terminal.
pub fn apply_text(model: &ThermalModel, json: &ApplyJson) -> String {
    let mut text = format!(
        "Thermal model: {} term(s), fitted on rows {}–{} ({:.0}–{:.0} min); prediction uncertainty {:.2} µm (1σ, time-blocked cross-validation, in the fit rows' conditions; beyond them it can be larger)\n",
        model.terms.len(),
        model.fit.first_row,
        model.fit.last_row,
        model.fit.from_s / 60.0,
        model.fit.to_s / 60.0,
        model.fit.cv_rms_um
    );
    for (label, figures) in [
        ("all rows", &json.all_rows),
        ("rows not fitted on", &json.outside_fit_rows),
    ] {
        if let Some(f) = figures {
            text.push_str(&format!(
                "  {label} ({}): drift rms {:.2} µm, max {:.2} µm; after compensation rms {:.2} µm, max {:.2} µm\n",
                f.before.rows, f.before.rms_um, f.before.max_um, f.after.rms_um, f.after.max_um
            ));
        }
    }
    if json.all_rows.is_none() {
        text.push_str(&format!(
            "  the log has no {:?} column: predictions only (--json)\n",
            model.fit.drift
        ));
    }
    text
}

/// How a summary says the validation: nothing for the blocked k-fold (the default).
fn validation_words(validation: Validation) -> &'static str {
    match validation {
        Validation::Blocked => "",
        Validation::Forward => " (each block predicted from the blocks before it)",
        Validation::Late => {
            " (the blocks in the last third of the rows, each predicted from every row before it)"
        }
    }
}

/// The fit report for the terminal.
pub fn fit_text(model: &ThermalModel) -> String {
    let f = &model.fit;
    let mut text = format!(
        "Thermal model of {:?} from rows {}–{} ({:.0}–{:.0} min), chosen from {} by {}-block time-blocked cross-validation{}{}\n",
        f.drift,
        f.first_row,
        f.last_row,
        f.from_s / 60.0,
        f.to_s / 60.0,
        f.candidates.join(", "),
        f.blocks,
        validation_words(f.validation),
        f.reference
            .as_deref()
            .map(|r| format!(" as rises over {r}"))
            .unwrap_or_default()
    );
    for t in &model.terms {
        text.push_str(&format!(
            "  {:<8} lag τ = {:>5.0} min  {:>+8.3} µm/K  from {:.2} °C\n",
            t.sensor,
            t.tau_s / 60.0,
            t.coefficient_um_per_k,
            t.reference_c
        ));
    }
    text.push_str(&format!(
        "  fit rms {:.2} µm; cross-validated rms {:.2} µm (the prediction's standard uncertainty in the fit rows' conditions; beyond them it can be larger)\n",
        f.fit_rms_um, f.cv_rms_um
    ));
    text
}

/// One sensor in `thermal evaluate --json`.
#[derive(Serialize)]
pub struct SensorJson {
    /// Column name.
    pub name: String,
    /// At the first row, °C.
    pub start_c: f64,
    /// At the last row, °C.
    pub end_c: f64,
    /// Largest minus smallest, K.
    pub range_k: f64,
    /// Largest rise over the start, K.
    pub max_rise_k: f64,
    /// When, min from the start.
    pub max_rise_at_min: f64,
}

/// `thermal evaluate --json`.
#[derive(Serialize)]
pub struct EvaluateJson {
    /// The ISO 230-3 test, as the user states it (`null`: not stated).
    pub test_type: Option<&'static str>,
    /// Rows.
    pub rows: usize,
    /// Duration, min.
    pub duration_min: f64,
    /// The largest drift from the start (signed), µm.
    pub max_drift_um: Option<f64>,
    /// When it occurred, min from the start.
    pub max_drift_at_min: Option<f64>,
    /// Largest minus smallest drift, µm.
    pub drift_range_um: Option<f64>,
    /// Each temperature.
    pub sensors: Vec<SensorJson>,
}

/// The JSON of an ISO 230-3 view.
pub fn evaluate_json(iso: &Iso230_3) -> EvaluateJson {
    EvaluateJson {
        test_type: iso.test_type.map(|t| t.title()),
        rows: iso.rows,
        duration_min: iso.duration_s / 60.0,
        max_drift_um: iso.max_drift.map(|d| d.0),
        max_drift_at_min: iso.max_drift.map(|d| d.1 / 60.0),
        drift_range_um: iso.drift_range_um,
        sensors: iso
            .sensors
            .iter()
            .map(|s| SensorJson {
                name: s.name.clone(),
                start_c: s.start_c,
                end_c: s.end_c,
                range_k: s.range_k,
                max_rise_k: s.max_rise_k,
                max_rise_at_min: s.max_rise_at_s / 60.0,
            })
            .collect(),
    }
}

/// The ISO 230-3 view for the terminal.
pub fn evaluate_text(json: &EvaluateJson) -> String {
    let mut text = format!(
        "ISO 230-3 thermal test: {}\n  duration {:.0} min, {} rows\n",
        json.test_type
            .unwrap_or("type not stated (--test etve, spindle or linear-axis)"),
        json.duration_min,
        json.rows
    );
    match (
        json.max_drift_um,
        json.max_drift_at_min,
        json.drift_range_um,
    ) {
        (Some(d), Some(at), Some(range)) => text.push_str(&format!(
            "  largest drift from the start {d:+.2} µm at {at:.0} min; range {range:.2} µm\n"
        )),
        _ => text.push_str("  drift: not recorded (name its column with --drift)\n"),
    }
    text.push_str("  sensor       start °C   end °C  range K  largest rise K  at min\n");
    for s in &json.sensors {
        text.push_str(&format!(
            "  {:<10} {:>9.2} {:>8.2} {:>8.2} {:>15.2} {:>7.0}\n",
            s.name, s.start_c, s.end_c, s.range_k, s.max_rise_k, s.max_rise_at_min
        ));
    }
    text
}

const PALETTE: [Rgb; 8] = [
    Rgb(31, 95, 170),
    Rgb(200, 82, 0),
    Rgb(40, 140, 60),
    Rgb(170, 40, 40),
    Rgb(120, 80, 160),
    Rgb(130, 90, 60),
    Rgb(200, 90, 170),
    Rgb(110, 110, 110),
];

/// The drift against time; with a model run, the prediction and the residual.
pub fn drift_chart(log: &ThermalLog, applied: Option<&Application>) -> Chart {
    let minutes: Vec<f64> = log.times_s.iter().map(|t| t / 60.0).collect();
    let line = |label: &str, color: Rgb, mark: Mark, values: &[f64]| Series {
        label: Some(label.to_string()),
        color,
        mark,
        points: minutes
            .iter()
            .copied()
            .zip(values.iter().copied())
            .collect(),
    };
    let mut series = Vec::new();
    if let Some(drift) = &log.drift {
        let start = drift.um[0];
        let measured: Vec<f64> = drift.um.iter().map(|v| v - start).collect();
        series.push(line("measured drift", PALETTE[0], Mark::Line(2), &measured));
    }
    if let Some(applied) = applied {
        series.push(line(
            "model",
            PALETTE[1],
            Mark::Dashed(2),
            &applied.predicted_um,
        ));
        if let Some(residual) = applied.residual_um() {
            series.push(line(
                "after compensation",
                PALETTE[2],
                Mark::Line(1),
                &residual,
            ));
        }
    }
    Chart {
        title: "Thermal drift".to_string(),
        x_label: "time [min]".to_string(),
        y_label: "drift [µm]".to_string(),
        series,
        y_range: None,
        polar: None,
    }
}

/// The temperatures against time.
pub fn temperature_chart(log: &ThermalLog) -> Chart {
    let minutes: Vec<f64> = log.times_s.iter().map(|t| t / 60.0).collect();
    let series = log
        .sensors
        .iter()
        .enumerate()
        .map(|(k, s)| Series {
            label: Some(s.name.clone()),
            color: PALETTE[k % PALETTE.len()],
            mark: if k < PALETTE.len() {
                Mark::Line(1)
            } else {
                Mark::Dashed(1)
            },
            points: minutes
                .iter()
                .copied()
                .zip(s.celsius.iter().copied())
                .collect(),
        })
        .collect();
    Chart {
        title: "Temperatures".to_string(),
        x_label: "time [min]".to_string(),
        y_label: "temperature [°C]".to_string(),
        series,
        y_range: None,
        polar: None,
    }
}

/// The thermal section of the HTML report (and of the web app's thermal
/// page): the ISO 230-3 figures, the drift and temperature plots, and with a
/// model its terms, its fit and the drift before and after it; with a
/// re-test's drift, the share the temperatures explain.
pub fn section_html(study: &Study, share: Option<&ShareView>) -> Result<String, PlotError> {
    let iso = evaluate_json(&study.iso);
    let mut html = String::from("<section id=\"thermal\">\n<h2>Thermal drift (ISO 230-3)</h2>\n");
    html.push_str(&format!(
        "<p>{}; {:.0} min, {} rows.</p>\n",
        esc(iso.test_type.unwrap_or("test type not stated")),
        iso.duration_min,
        iso.rows
    ));
    html.push_str("<table class=\"keep\"><tbody>\n");
    match (iso.max_drift_um, iso.max_drift_at_min, iso.drift_range_um) {
        (Some(d), Some(at), Some(range)) => html.push_str(&format!(
            "<tr><th>largest drift from the start</th><td class=\"num\" data-key=\"thermal.max_drift_um\" data-um=\"{d}\">{d:+.2} µm</td><td>at {at:.0} min</td></tr>\n<tr><th>drift range</th><td class=\"num\" data-key=\"thermal.drift_range_um\" data-um=\"{range}\">{range:.2} µm</td><td></td></tr>\n"
        )),
        _ => html.push_str("<tr><th>drift</th><td colspan=\"2\">not recorded in the log</td></tr>\n"),
    }
    html.push_str("</tbody></table>\n");
    html.push_str("<table class=\"keep\"><thead><tr><th>sensor</th><th>start [°C]</th><th>end [°C]</th><th>range [K]</th><th>largest rise [K]</th><th>at [min]</th></tr></thead><tbody>\n");
    for s in &iso.sensors {
        html.push_str(&format!(
            "<tr><th>{}</th><td class=\"num\">{:.2}</td><td class=\"num\">{:.2}</td><td class=\"num\">{:.2}</td><td class=\"num\">{:.2}</td><td class=\"num\">{:.0}</td></tr>\n",
            esc(&s.name),
            s.start_c,
            s.end_c,
            s.range_k,
            s.max_rise_k,
            s.max_rise_at_min
        ));
    }
    html.push_str("</tbody></table>\n");
    html.push_str(&svg_figure(&drift_chart(
        &study.log,
        study.applied.as_ref(),
    ))?);
    html.push_str(&svg_figure(&temperature_chart(&study.log))?);
    if let (Some(model), Some(applied)) = (&study.model, &study.applied) {
        html.push_str(&model_html(model, &apply_json(model, &study.log, applied)));
    }
    if let Some(share) = share {
        html.push_str(&format!(
            "<h3>The re-test's drift</h3>\n<p>{}</p>\n",
            esc(&share.text)
        ));
    }
    html.push_str("</section>\n");
    Ok(html)
}

fn model_html(model: &ThermalModel, json: &ApplyJson) -> String {
    let f = &model.fit;
    let mut html = format!(
        "<h3>Model of the drift from the temperatures</h3>\n<p>Each term is a sensor through a first-order lag (time constant τ), times a coefficient; chosen from {} by {}-block time-blocked cross-validation{} on rows {}–{} ({:.0}–{:.0} min){}.</p>\n",
        esc(&f.candidates.join(", ")),
        f.blocks,
        validation_words(f.validation),
        f.first_row,
        f.last_row,
        f.from_s / 60.0,
        f.to_s / 60.0,
        f.reference
            .as_deref()
            .map(|r| format!(", each a rise over {}", esc(r)))
            .unwrap_or_default()
    );
    html.push_str("<table class=\"keep\"><thead><tr><th>sensor</th><th>τ [min]</th><th>coefficient [µm/K]</th><th>from [°C]</th></tr></thead><tbody>\n");
    for t in &model.terms {
        html.push_str(&format!(
            "<tr><th>{}</th><td class=\"num\">{:.0}</td><td class=\"num\">{:+.3}</td><td class=\"num\">{:.2}</td></tr>\n",
            esc(&t.sensor),
            t.tau_s / 60.0,
            t.coefficient_um_per_k,
            t.reference_c
        ));
    }
    html.push_str("</tbody></table>\n");
    html.push_str(&format!(
        "<p>Fit rms <span data-key=\"thermal.fit_rms_um\" data-um=\"{0}\">{0:.2}</span> µm; cross-validated rms <span data-key=\"thermal.cv_rms_um\" data-um=\"{1}\">{1:.2}</span> µm (the prediction's standard uncertainty in the fit rows' conditions; beyond them it can be larger).</p>\n",
        f.fit_rms_um, f.cv_rms_um
    ));
    let rows = [
        ("all rows", "all_rows", &json.all_rows),
        (
            "rows not fitted on",
            "outside_fit_rows",
            &json.outside_fit_rows,
        ),
    ];
    if rows.iter().any(|r| r.2.is_some()) {
        html.push_str("<table class=\"keep\"><thead><tr><th>drift [µm]</th><th>rows</th><th>rms before</th><th>largest before</th><th>rms after</th><th>largest after</th></tr></thead><tbody>\n");
        for (label, key, figures) in rows {
            if let Some(b) = figures {
                let cell = |name: &str, v: f64| {
                    format!(
                        "<td class=\"num\" data-key=\"thermal.{key}.{name}\" data-um=\"{v}\">{v:.2}</td>"
                    )
                };
                html.push_str(&format!(
                    "<tr><th>{label}</th><td class=\"num\">{}</td>{}{}{}{}</tr>\n",
                    b.before.rows,
                    cell("before.rms_um", b.before.rms_um),
                    cell("before.max_um", b.before.max_um),
                    cell("after.rms_um", b.after.rms_um),
                    cell("after.max_um", b.after.max_um)
                ));
            }
        }
        html.push_str("</tbody></table>\n");
    }
    html
}

fn svg_figure(chart_data: &Chart) -> Result<String, PlotError> {
    let bytes = chart(chart_data, PlotFormat::Svg)?;
    let svg = String::from_utf8_lossy(&bytes);
    let svg = svg.replacen(
        "<svg ",
        &format!(
            "<svg role=\"img\" aria-label=\"{}\" ",
            esc(&chart_data.title)
        ),
        1,
    );
    Ok(format!("<figure class=\"plot keep\">{svg}</figure>\n"))
}

/// `page` (the report's HTML) with `section` before its signatures (or
/// before `</body>`, or at the end).
pub fn insert_section(page: &str, section: &str) -> String {
    let at = page
        .find("<section id=\"signatures\"")
        .or_else(|| page.find("</body>"))
        .unwrap_or(page.len());
    format!("{}{}{}", &page[..at], section, &page[at..])
}

/// The share of a re-test's drift that the logged temperatures explain, as
/// the terminal, the JSON and the report say it.
#[derive(Clone, Debug, Serialize)]
pub struct ShareView {
    /// The found drift, µm/h (absent when not computed).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub found_um_per_h: Option<f64>,
    /// The model's drift over the readings, µm/h.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub explained_um_per_h: Option<f64>,
    /// explained / found.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub share: Option<f64>,
    /// One sentence.
    pub text: String,
}

/// A command's JSON with the thermal share added: the report's own keys
/// first, in its order, then `"thermal"`.
#[derive(Serialize)]
pub struct WithShare<'a, T> {
    /// The command's JSON.
    #[serde(flatten)]
    pub report: &'a T,
    /// The share.
    pub thermal: ShareView,
}

impl ShareView {
    /// Of a computed share.
    pub fn of(share: &ThermalShare) -> ShareView {
        ShareView {
            found_um_per_h: Some(share.found_um_per_h),
            explained_um_per_h: Some(share.explained_um_per_h),
            share: Some(share.share),
            text: format!(
                "The drift found, {:+.2} µm/h over {:.1} h, is {:.0} % explained by the temperatures logged during the re-test: the thermal model predicts {:+.2} µm/h at the readings' times; the rest ({:+.2} µm/h) is not thermal as far as the logged sensors tell.",
                share.found_um_per_h,
                share.span_h,
                100.0 * share.share,
                share.explained_um_per_h,
                share.found_um_per_h - share.explained_um_per_h
            ),
        }
    }

    /// Why it was not computed, with what the test file records.
    pub fn not_computed(why: &str, recorded: &[RecordedChange]) -> ShareView {
        let mut text = why.to_string();
        if !recorded.is_empty() {
            let list: Vec<String> = recorded
                .iter()
                .map(|r| format!("{} {:.2} → {:.2} °C", r.name, r.start_c, r.end_c))
                .collect();
            text.push_str(&format!(
                "; the re-test file records start and end temperatures only ({}), which cannot apportion a drift",
                list.join(", ")
            ));
        }
        ShareView {
            found_um_per_h: None,
            explained_um_per_h: None,
            share: None,
            text,
        }
    }
}

/// The web app's thermal page: the upload form and, after a request, the
/// section (or the error).
pub fn page_html(body: &str, generator: &str) -> String {
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<meta name=\"generator\" content=\"{}\">\n<title>Thermal drift (ISO 230-3)</title>\n<style>body{{font-family:sans-serif;max-width:60rem;margin:1rem auto;padding:0 1rem}}table{{border-collapse:collapse;margin:.5rem 0}}th,td{{border:1px solid #bbb;padding:.2rem .5rem}}td.num{{text-align:right}}figure svg{{max-width:100%;height:auto}}.error{{color:#a00}}label{{display:block;margin:.3rem 0}}</style>\n</head>\n<body>\n<p><a href=\"/\">axcomp</a></p>\n<h1>Thermal drift</h1>\n<form method=\"post\" action=\"/thermal\" enctype=\"multipart/form-data\">\n<label>Thermal log (CSV) <input type=\"file\" name=\"log\" required></label>\n<label>Drift column <input name=\"drift\" placeholder=\"delta L\"></label>\n<label>Seconds between rows (a log without a time column) <input name=\"sample_interval\" inputmode=\"decimal\"></label>\n<label>Model (TOML, from axcomp thermal fit; none: fitted on the log) <input type=\"file\" name=\"model\"></label>\n<label>Fit on rows FIRST-LAST <input name=\"rows\" placeholder=\"1-1500\"></label>\n<label>Sensors to choose from <input name=\"sensors\" placeholder=\"T0,T1,T2\"></label>\n<label>Reference sensor (auto: each sensor tried, and none, the best kept) <input name=\"reference\" placeholder=\"T14 or auto\"></label>\n<label>Cross-validation <select name=\"validation\">{}</select></label>\n<label>ISO 230-3 test <select name=\"test\"><option value=\"\">not stated</option>{}</select></label>\n<button type=\"submit\">Evaluate and fit</button>\n</form>\n{body}</body>\n</html>\n",
        esc(generator),
        Validation::ALL
            .iter()
            .map(|v| format!(
                "<option value=\"{}\">{}</option>",
                v.name(),
                validation_choice(*v)
            ))
            .collect::<String>(),
        TestType::ALL
            .iter()
            .map(|t| format!("<option value=\"{}\">{}</option>", t.name(), t.title()))
            .collect::<String>(),
    )
}

/// How the form offers a validation.
fn validation_choice(validation: Validation) -> &'static str {
    match validation {
        Validation::Blocked => "blocked: each block predicted from all the others",
        Validation::Forward => {
            "forward: each block predicted from the blocks before it (Bergmeir and Benítez 2012)"
        }
        Validation::Late => {
            "late: the blocks in the last third of the rows, each predicted from every row before it (Tashman 2000)"
        }
    }
}

/// The model file a fit on the web page made, as `thermal fit` writes it,
/// to copy or save (`thermal apply`, `thermal hal`, `report --thermal-model`).
pub fn model_file_html(model: &ThermalModel) -> String {
    format!(
        "<details open>\n<summary>Model file (TOML, as <code>axcomp thermal fit</code> writes it)</summary>\n<pre id=\"model-toml\">{}</pre>\n</details>\n",
        esc(&model_toml(model))
    )
}

// axcomp serve: the page. Plain JavaScript, no library, no network but this
// app's own API (src/serve/mod.rs). Every number shown comes from the JSON
// the CLI prints with --json; the files come from the server byte for byte.
"use strict";

const $ = (id) => document.getElementById(id);
// `existing` is step 2's table that was active during the test (`convert --existing`), sent as
// `table` with the test; step 3's `table` is the one active during the re-test.
const files = { file: [], after: [], table: [], existing: [], machine: [], fanuc_parameters: [] };
// The rescaled Fanuc file of the last conversion (`--fanuc-rescaled`), for its download.
let rescaled = null;
// The limits typed next to the figures, µm, by figure key (`A`, `R_up`).
const limits = {};
let busy = 0;
let lastConvert = null;

// Requests in flight, for whoever waits for the page to settle (the tests).
function track(delta) {
  busy += delta;
  document.body.dataset.busy = String(busy);
}

function text(value, digits = 2) {
  if (value === null || value === undefined) return "not evaluated";
  if (typeof value === "number") return value.toFixed(digits);
  return String(value);
}

// A position of an answer with its unit, as the JSON keys name it: `KEY_mm`
// on a linear axis, `KEY_deg` on a rotary one; the number as sent unless
// `digits` is given.
function position(answer, key, digits) {
  const [value, unit] = answer[key + "_deg"] !== undefined
    ? [answer[key + "_deg"], "°"]
    : [answer[key + "_mm"], " mm"];
  if (value === null || value === undefined) return "not evaluated";
  return (digits === undefined ? String(value) : text(value, digits)) + unit;
}

// A deviation field of an answer and its unit: `KEY_um` on a linear axis,
// `KEY_arcsec` on a rotary one (the web app reports angles in ″).
function deviation(answer, key) {
  return answer[key + "_um"] !== undefined
    ? [answer[key + "_um"], " µm"]
    : [answer[key + "_arcsec"], "″"];
}

function element(tag, content, className) {
  const node = document.createElement(tag);
  if (content !== undefined) node.textContent = content;
  if (className) node.className = className;
  return node;
}

function row(table, cells, header = false) {
  const tr = table.insertRow();
  for (const cell of cells) {
    tr.appendChild(element(header ? "th" : "td", cell));
  }
}

function showError(id, message) {
  const box = $(id);
  box.textContent = message || "";
  box.hidden = !message;
}

// The page's settings and files as a form for the API.
function form(fields) {
  const data = new FormData();
  for (const field of fields.concat(["machine", "fanuc_parameters"])) {
    for (const file of files[field]) data.append(field, file, file.name);
  }
  for (const id of ["axis", "standard", "decision"]) {
    if ($(id).value.trim()) data.append(id, $(id).value.trim());
  }
  const given = Object.entries(limits).filter(([, v]) => v !== "").map(([k, v]) => k + "=" + v);
  if (given.length) data.append("limits", given.join(","));
  return data;
}

function tableForm(fields) {
  const data = form(fields);
  for (const id of ["controller", "mode", "start", "step", "count", "reference", "extrapolate", "linuxcnc_type"]) {
    const value = $(id).value.trim();
    if (value) data.append(id, value);
  }
  if ($("fanuc_rescaled").checked) data.append("fanuc_rescaled", "1");
  return data;
}

// Step 2's request: the test, the table that was active during it, the settings
// (`convert FILE --existing TABLE …`).
function convertForm() {
  const data = tableForm(["file"]);
  for (const file of files.existing) data.append("table", file, file.name);
  return data;
}

async function post(path, data) {
  track(1);
  try {
    const response = await fetch(path, { method: "POST", body: data });
    if (!response.ok) {
      let message = response.status + " " + response.statusText;
      try {
        message = (await response.json()).error;
      } catch (_) { /* not JSON: keep the status */ }
      throw new Error(message);
    }
    return response;
  } finally {
    track(-1);
  }
}

// Saves `blob` as a download named `name`.
function save(blob, name) {
  const link = element("a");
  link.href = URL.createObjectURL(blob);
  link.download = name;
  document.body.appendChild(link);
  link.click();
  link.remove();
  setTimeout(() => URL.revokeObjectURL(link.href), 60000);
  document.body.dataset.downloaded = link.download;
}

// Saves a response as a download under the server's name for it.
async function download(path, data, errorId) {
  showError(errorId, "");
  try {
    const response = await post(path, data);
    const disposition = response.headers.get("Content-Disposition") || "";
    const match = /filename="([^"]+)"/.exec(disposition);
    save(await response.blob(), match ? match[1] : "download");
  } catch (error) {
    showError(errorId, error.message);
  }
}

function showEvaluation(answer) {
  const e = answer.evaluation;
  const header = $("header");
  header.replaceChildren();
  const m = e.metadata || {};
  const entries = [
    ["File", (e.source_file || "") + " (" + e.format + ", " + e.length_unit + ")"],
    ["Machine", [m.machine, m.serial_number && "serial " + m.serial_number].filter(Boolean).join(", ") || "not recorded"],
    ["Axis", e.axis_source && e.axis_source.kind === "not_recorded" ? "not recorded (type it in Axis)" : e.axis],
    ["Date", m.date || "not recorded"],
    ["Runs", e.runs.up + "↑ " + e.runs.down + "↓"],
    ["Test", e.test_conformance.title],
  ];
  for (const [name, value] of entries) {
    header.appendChild(element("dt", name));
    header.appendChild(element("dd", value));
  }
  const figures = $("figures");
  figures.replaceChildren();
  const unit = e.figures_um ? "um" : "arcsec";
  const values = e.figures_um || e.figures_arcsec || {};
  const uncertainty = e.uncertainty_um || {};
  row(figures, unit === "um" ? ["figure", "µm", "U", "limit [µm]"] : ["figure", "″", "U"], true);
  for (const [key, value] of Object.entries(values)) {
    row(figures, [key.replace("_up", " ↑").replace("_down", " ↓").replace("B_mean", "B̄"), text(value),
      uncertainty[key] ? "± " + text(uncertainty[key]) : ""]);
    if (unit !== "um") continue;
    // Limits are µm, for linear axes only (as --limit).
    const input = element("input");
    input.id = "limit-" + key;
    input.size = 5;
    input.inputMode = "decimal";
    input.value = limits[key] || "";
    const check = e.verdict && e.verdict.checks.find((c) => c.figure === key);
    if (check && !input.value) input.placeholder = text(check.limit_um);
    input.addEventListener("change", () => { limits[key] = input.value.trim(); evaluate(); });
    figures.rows[figures.rows.length - 1].insertCell().appendChild(input);
  }
  showVerdict(e.verdict);
  showEdlen(e.refractive_index);
  const environment = $("environment");
  environment.replaceChildren();
  const env = e.environment || {};
  const span = (pair, digits) => pair ? text(pair.start, digits) + " → " + text(pair.end, digits) : "not recorded";
  row(environment, ["air temperature [°C]", span(env.air_temperature_c, 2)]);
  row(environment, ["air pressure [kPa]", span(env.air_pressure_kpa, 2)]);
  row(environment, ["humidity [%RH]", span(env.air_humidity_pct, 1)]);
  (env.material_temperature_c || []).forEach((pair, i) => {
    if (pair.start !== null) row(environment, ["material " + (i + 1) + " [°C]", span(pair, 2)]);
  });
  row(environment, ["environmental factor [µm/mm]", span(env.environmental_factor_um, 8)]);
  const outliers = $("outliers");
  outliers.replaceChildren();
  if (e.outliers.length) {
    outliers.appendChild(element("h3", "Suspected outlier runs (kept in the figures)"));
    const list = element("ul");
    for (const o of e.outliers) {
      list.appendChild(element("li", "run " + o.run + " " + o.direction + ": score " + text(o.score) +
        ", worst at " + position(o, "worst_target")));
    }
    outliers.appendChild(list);
  }
  const warnings = $("warnings");
  warnings.replaceChildren(...e.warnings.map((w) => element("li", w)));
  $("deviation").innerHTML = answer.deviation_svg || "";
  $("evaluation").hidden = false;
  for (const id of ["step-table", "step-retest", "step-report"]) $(id).hidden = false;
}

// The verdict as evaluate --json gives it: the rule, then one line per check.
function showVerdict(verdict) {
  const box = $("verdict");
  const checks = $("checks");
  checks.replaceChildren();
  if (!verdict) {
    box.textContent = "";
    box.className = "";
    delete document.body.dataset.verdict;
    return;
  }
  const word = { pass: "PASS", fail: "FAIL", "not-proven": "NOT PROVEN" }[verdict.conformance] || verdict.conformance;
  box.textContent = word + " (" + verdict.decision + ")" + (verdict.failed.length ? ": " + verdict.failed.join(", ") + " not within the limits" : "");
  box.className = "verdict " + verdict.conformance;
  for (const c of verdict.checks) {
    checks.appendChild(element("li", c.figure + " " + text(c.value_um) + " µm against " + text(c.limit_um) +
      " µm" + (c.U_um !== null && c.U_um !== undefined ? " (U ± " + text(c.U_um) + ")" : "") + ": " + c.conformance +
      " · " + c.limit_source + (c.limit_derivation ? ", " + c.limit_derivation : "")));
  }
  document.body.dataset.verdict = verdict.conformance;
}

// The Edlén check as evaluate --json gives it (no physics here).
function showEdlen(check) {
  const table = $("edlen");
  table.replaceChildren();
  if (!check) return;
  row(table, ["", "factor [µm]", "n implied", "n Edlén", "difference [ppm]"], true);
  const notes = [];
  for (const when of ["start", "end"]) {
    const at = check[when];
    if (at.missing.length) {
      notes.push(when + ": not checked, the file lacks " + at.missing.join(", "));
      continue;
    }
    row(table, [when, text(at.factor_um, 8), text(at.implied_n, 9), text(at.edlen_n, 9),
      (at.difference_ppm >= 0 ? "+" : "") + text(at.difference_ppm, 2) + (at.agrees ? " ✓" : " ✗")]);
  }
  notes.push("agreement within ±" + check.agreement_ppm + " ppm; vacuum wavelength " + check.vacuum_wavelength_um +
    " µm" + (check.wavelength_assumed ? " (assumed: the file records none)" : ""));
  $("edlen-note").textContent = notes.join("; ");
}

async function evaluate() {
  showError("error", "");
  if (!files.file.length) return;
  try {
    const answer = await (await post("/api/evaluate", form(["file"]))).json();
    showEvaluation(answer);
    document.body.dataset.evaluated = answer.evaluation.source_file || "";
    await convert();
  } catch (error) {
    $("evaluation").hidden = true;
    for (const id of ["step-table", "step-retest", "step-report"]) $(id).hidden = true;
    showError("error", error.message);
    document.body.dataset.evaluated = "";
  }
}

function showTable(answer, prefix) {
  const c = answer.convert;
  $(prefix + "preview").textContent = answer.text;
  return c;
}

async function convert() {
  showError("table-error", "");
  if (!files.file.length) return;
  const request = convertForm();
  lastConvert = request;
  try {
    const answer = await (await post("/api/convert", request)).json();
    if (lastConvert !== request) return;
    const c = showTable(answer, "");
    const step = c.step_mm ?? c.step_deg;
    $("table-summary").textContent = answer.file_name + ": " + c.count + " points, " + c.mode +
      (step ? ", step " + position(c, "step") : "") + ", zero at " + position(c, "reference", 3) +
      ", file in " + c.file_unit;
    $("backlash").textContent = c.backlash_parameter
      ? "Backlash: " + c.backlash_parameter.name + " = " + c.backlash_parameter.value + " " + c.backlash_parameter.unit +
        " (" + c.backlash_parameter.sign + ")"
      : (c.backlash_note || "");
    $("activation").textContent = c.activation;
    // What an update kept and changed, and what a one-direction table is (convert prints the same).
    $("table-notes").replaceChildren(...[
      ...(c.update ? c.update.lines.map((line) => "Update: " + line) : []),
      ...(c.notes || []).map((note) => "Note: " + note),
    ].map((line) => element("li", line)));
    $("table-plot").innerHTML = answer.table_svg || "";
    $("table-result").hidden = false;
    $("download").dataset.name = answer.file_name;
    rescaled = answer.fanuc_rescaled;
    if (rescaled) {
      $("rescaled-name").textContent = rescaled.file_name;
      $("rescaled-instruction").textContent = rescaled.instruction;
      $("rescaled-preview").textContent = rescaled.text;
    }
    $("rescaled").hidden = !rescaled;
    document.body.dataset.converted = c.controller + ":" + answer.file_name;
  } catch (error) {
    $("table-result").hidden = true;
    showError("table-error", error.message);
    document.body.dataset.converted = "";
  }
}

async function retest() {
  showError("retest-error", "");
  if (!files.after.length || !files.file.length) return;
  try {
    const answer = await (await post("/api/retest", tableForm(["file", "after", "table"]))).json();
    const d = answer.diagnosis;
    const [before, unit] = deviation(d, "residual_before");
    const [after] = deviation(d, "residual_after");
    $("residual").textContent = "Residual rms " + text(before.rms) + unit + " → " +
      text(after.rms) + unit + " with the effects found" +
      (d.unexplained.significant ? "; structure no effect explains remains" : "; nothing left unexplained");
    $("effects").replaceChildren(...(d.effects.length
      ? d.effects.map((e) => element("li", e.kind + ": " + e.explanation))
      : [element("li", "no effect beyond what the prediction carries")]));
    $("retest-warnings").replaceChildren(...answer.warnings.map((w) => element("li", w)));
    $("residual-plot").innerHTML = answer.residual_svg || "";
    if (answer.next) {
      $("next-name").textContent = answer.next.file_name;
      $("next-preview").textContent = answer.next.text;
      $("next").hidden = false;
    } else {
      $("next").hidden = true;
    }
    $("retest-result").hidden = false;
    $("report-extra").textContent = ", the before/after comparison and the diagnosis";
  } catch (error) {
    $("retest-result").hidden = true;
    showError("retest-error", error.message);
  }
}

function pick(field, list, then) {
  files[field] = Array.from(list).slice(0, field === "file" ? 2 : 1);
  then();
}

function dropZone(zone, field, then) {
  zone.addEventListener("dragover", (event) => {
    event.preventDefault();
    zone.classList.add("over");
  });
  zone.addEventListener("dragleave", () => zone.classList.remove("over"));
  zone.addEventListener("drop", (event) => {
    event.preventDefault();
    zone.classList.remove("over");
    pick(field, event.dataTransfer.files, then);
  });
}

async function start() {
  const options = await (await fetch("/api/options")).json();
  for (const name of options.controllers) $("controller").appendChild(new Option(name, name, false, name === "tnc640"));
  for (const s of options.standards) $("standard").appendChild(new Option(s.name, s.key));
  $("footer").textContent = "axcomp " + options.version + " · uploads up to " +
    Math.round(options.upload_limit_bytes / 1048576) + " MB, kept in memory only";
  $("file").addEventListener("change", (event) => pick("file", event.target.files, evaluate));
  $("after").addEventListener("change", (event) => pick("after", event.target.files, retest));
  $("table").addEventListener("change", (event) => pick("table", event.target.files, retest));
  $("machine").addEventListener("change", (event) => pick("machine", event.target.files, () => { evaluate().then(retest); }));
  $("decision").addEventListener("change", evaluate);
  dropZone($("drop-file"), "file", evaluate);
  for (const id of ["axis", "standard"]) $(id).addEventListener("change", evaluate);
  for (const id of ["controller", "mode", "start", "step", "count", "reference", "extrapolate", "linuxcnc_type"]) {
    $(id).addEventListener("change", () => { convert(); retest(); });
  }
  $("download").addEventListener("click", () => download("/api/table", convertForm(), "table-error"));
  $("existing").addEventListener("change", (event) => pick("existing", event.target.files, convert));
  $("fanuc_parameters").addEventListener("change", (event) => pick("fanuc_parameters", event.target.files, () => { convert(); retest(); }));
  $("fanuc_rescaled").addEventListener("change", convert);
  $("download-rescaled").addEventListener("click", () => {
    if (rescaled) save(new Blob([rescaled.text], { type: "application/octet-stream" }), rescaled.file_name);
  });
  $("download-next").addEventListener("click", () => download("/api/table", tableForm(["file", "after", "table"]), "retest-error"));
  $("report").addEventListener("click", () => {
    const data = form(["file", "after", "table"]);
    if ($("diagnose").checked && files.after.length) data.append("diagnose", "yes");
    download("/api/report", data, "report-error");
  });
  document.body.dataset.ready = "yes";
}

start().catch((error) => showError("error", error.message));

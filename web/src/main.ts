// The page of `pneumid app`: data -> identification -> controller -> run -> export.
// Plain TypeScript and DOM; every action is one call of the HTTP JSON API.
import './style.css';
import { call, ApiError, withToken, streamUrl, DataSet, IdentifyResult, ModelEntry } from './api';
import { TimePlot, COLORS, interp } from './plot';

const $ = <T extends HTMLElement = HTMLElement>(id: string): T => {
  const el = document.getElementById(id);
  if (!el) throw new Error('missing element #' + id);
  return el as T;
};

const METHODS = [
  'reaction-curve', 'tangent', 'smith', 'sundaresan', 'broida', 'sopdt', 'ptn', 'strejc', 'areas',
  'fit-p1d', 'fit-p2d', 'fit-p2du', 'fit-p3d', 'fit-p1di', 'arx', 'armax', 'oe', 'bj', 'iv4', 'n4sid',
  'static-map', 'hammerstein', 'wiener', 'hw', 'narx', 'affine-narx',
];
const DEFAULT_METHODS = ['reaction-curve', 'arx', 'fit-p1d'];
const METRIC_KEYS: [string, string][] = [
  ['rise_time', 'rise time, first step [s]'],
  ['overshoot_percent', 'overshoot, worst step [%]'],
  ['settling_time', 'settling time, worst step [s]'],
  ['steady_state_error', 'steady-state error, end of the run'],
  ['worst_steady_state_error', 'steady-state error, worst step'],
  ['iae', 'IAE'],
  ['ise', 'ISE'],
  ['itae', 'ITAE'],
  ['tv_u', 'total variation of u'],
  ['first_move', 'first move'],
  ['u_min', 'u min'],
  ['u_max', 'u max'],
  ['settled', 'every step settled'],
  ['load_peak_deviation', 'load: peak deviation'],
  ['load_recovery_time', 'load: recovery time [s]'],
];

// State of the page, also exposed as window.pneumid for scripts and tests.
const state = {
  dir: '',
  data: null as DataSet | null,
  dataSource: null as { path?: string; file?: File } | null,
  identify: null as IdentifyResult | null,
  identifyMethods: [] as string[],
  identifyDetrend: 'none',
  model: '' as string, // method of the chosen model
  control: null as any,
  controlCount: 0, // closed-loop redraws done
  controlLatency: [] as number[], // ms from the change to the redraw, per redraw
  controlIdle: true, // no change waits for its closed-loop redraw
  controlTimings: [] as { server: number; draw: number }[], // ms of the request and of the redraw
  tune: null as any,
  run: { state: 'idle', samples: 0, points: 0, frames: 0, summary: null as any },
  commission: null as any, // the answer of POST /api/commission
  baseline: null as any, // a design kept for comparison: {label, trace, metrics}
  validation: null as DataSet | null, // the validation data set (identification and views)
  views: null as any, // POST /api/model/views of the chosen model
  view: 'data', // the view shown: data, step, bode, residuals
  excluded: [] as string[], // identified models whose responses diverge (not drawn on the shared axis)
};
(window as any).pneumid = state;

// ---------------------------------------------------------------------------
// Errors: each section has its element of class "error"
// ---------------------------------------------------------------------------
function showError(id: string, e: unknown): void {
  if ((e as Error)?.name === 'AbortError') return;
  const el = $(id);
  el.textContent = e instanceof ApiError || e instanceof Error ? e.message : String(e);
  el.hidden = false;
  console.error(e);
}
function clearError(id: string): void {
  const el = $(id);
  el.hidden = true;
  el.textContent = '';
}

// Results that no longer describe the page's inputs (another file, a failed
// request) are greyed (class "stale", with the reason as a tooltip) until redrawn.
function markStale(ids: string[], reason: string): void {
  for (const id of ids) {
    const el = document.getElementById(id);
    if (!el) continue;
    el.classList.add('stale');
    el.title = reason;
  }
}
function clearStale(ids: string[]): void {
  for (const id of ids) {
    const el = document.getElementById(id);
    if (!el) continue;
    el.classList.remove('stale');
    el.removeAttribute('title');
  }
}
const IDENTIFY_RESULTS = ['fit-table', 'identify-plot', 'identify-failures'];
const CONTROL_RESULTS = ['control-plot', 'control-u-plot', 'metrics', 'review'];

function fmt(v: unknown, digits = 4): string {
  if (v === null || v === undefined) return '—';
  if (typeof v === 'number') {
    if (!Number.isFinite(v)) return String(v);
    if (v !== 0 && (Math.abs(v) >= 1e5 || Math.abs(v) < 1e-3)) return v.toExponential(digits - 1);
    return String(Number(v.toPrecision(digits)));
  }
  if (typeof v === 'boolean') return v ? 'yes' : 'no';
  if (Array.isArray(v)) {
    const items = v.slice(0, 6).map((x) => fmt(x, digits));
    return '[' + items.join(', ') + (v.length > 6 ? ', …' : '') + ']';
  }
  if (typeof v === 'object') return JSON.stringify(v);
  return String(v);
}

function debounce(fn: () => void, ms: number): (() => void) & { pending: () => boolean } {
  let timer: number | undefined;
  const f = () => {
    if (timer !== undefined) clearTimeout(timer);
    timer = window.setTimeout(() => {
      timer = undefined;
      fn();
    }, ms);
  };
  f.pending = () => timer !== undefined;
  return f;
}

function download(blob: Blob, name: string): void {
  const done = document.getElementById('export-state');
  if (done) done.textContent = `${name} downloaded (${humanSize(blob.size)}, ${new Date().toLocaleTimeString()})`;
  const a = document.createElement('a');
  a.href = URL.createObjectURL(blob);
  a.download = name;
  document.body.appendChild(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 10000);
}

// ---------------------------------------------------------------------------
// (1) Data
// ---------------------------------------------------------------------------
const dataPlot = new TimePlot($('data-plot'));

async function listFiles(dir: string): Promise<void> {
  clearError('data-error');
  try {
    const res = await call<{ dir: string; entries: { name: string; type: string; size?: number }[] }>(
      'GET', '/api/files?dir=' + encodeURIComponent(dir));
    // the root is "" (the server may say ".")
    state.dir = (res.dir ?? dir).replace(/^\.\/?/, '').replace(/\/$/, '');
    $('files-dir').textContent = '/' + state.dir;
    const ul = $('files');
    ul.innerHTML = '';
    const entries = [...res.entries].sort((a, b) =>
      a.type === b.type ? a.name.localeCompare(b.name) : a.type === 'dir' ? -1 : 1);
    if (entries.length === 0) {
      const li = document.createElement('li');
      li.className = 'muted';
      li.textContent = 'no data files here';
      ul.appendChild(li);
    }
    fillValidationChoices(entries.filter((e) => e.type === 'file').map((e) => (state.dir ? state.dir + '/' : '') + e.name));
    for (const e of entries) {
      const li = document.createElement('li');
      li.dataset.name = e.name;
      li.dataset.type = e.type;
      const name = document.createElement('span');
      name.textContent = e.type === 'dir' ? e.name + '/' : e.name;
      const size = document.createElement('span');
      size.className = 'size';
      size.textContent = e.type === 'dir' ? '' : e.size !== undefined ? humanSize(e.size) : '';
      li.append(name, size);
      const rel = state.dir ? state.dir.replace(/\/$/, '') + '/' + e.name : e.name;
      li.addEventListener('click', () => {
        if (e.type === 'dir') void listFiles(rel);
        else void openFile(rel);
      });
      ul.appendChild(li);
    }
  } catch (e) {
    showError('data-error', e);
  }
}

function humanSize(n: number): string {
  if (n < 1024) return n + ' B';
  if (n < 1024 * 1024) return (n / 1024).toFixed(1) + ' kB';
  return (n / 1024 / 1024).toFixed(1) + ' MB';
}

function columnChoice(): { t?: string; u?: string; y?: string } {
  const pick = (id: string) => ($(id) as HTMLSelectElement).value || undefined;
  return { t: pick('col-t'), u: pick('col-u'), y: pick('col-y') };
}

async function openFile(path: string, columns: { t?: string; u?: string; y?: string } = {}): Promise<void> {
  clearError('data-error');
  $('data-info').textContent = 'opening ' + path + ' …';
  try {
    const ds = await call<DataSet>('POST', '/api/data/open', { body: { path, ...columns } });
    state.dataSource = { path };
    setData(ds);
    for (const li of $('files').querySelectorAll('li')) {
      li.classList.toggle('active', (li as HTMLElement).dataset.name === path.split('/').pop());
    }
  } catch (e) {
    $('data-info').textContent = 'No data open.';
    showError('data-error', e);
  }
}

async function uploadFile(file: File, columns: { t?: string; u?: string; y?: string } = {}): Promise<void> {
  clearError('data-error');
  $('data-info').textContent = 'uploading ' + file.name + ' …';
  try {
    let q = '/api/data/upload?name=' + encodeURIComponent(file.name);
    for (const [k, v] of Object.entries(columns)) if (v) q += '&' + k + '=' + encodeURIComponent(v);
    const ds = await call<DataSet>('POST', q, { raw: file, contentType: 'text/csv' });
    state.dataSource = { file };
    setData(ds);
  } catch (e) {
    $('data-info').textContent = 'No data open.';
    showError('data-error', e);
  }
}

// A new data set: the previous one's identification is cleared (its models
// describe other data) and the closed loop designed from them is greyed.
function clearIdentify(): void {
  state.identify = null;
  state.identifyMethods = [];
  $('fit-table').querySelector('tbody')!.innerHTML = '';
  identifyPlot.destroy();
  $('identify-failures').innerHTML = '';
  $('identify-failures').hidden = true;
  clearStale(IDENTIFY_RESULTS);
  clearError('identify-error');
  ($('export-model') as HTMLButtonElement).disabled = true;
  state.views = null;
  $('views').hidden = true;
  viewsPlot.destroy();
  viewsPlot2.destroy();
  if (state.model) {
    state.model = '';
    $('ctl-model').textContent = 'none';
    markStale(CONTROL_RESULTS, 'designed from the models of the previous data: identify again');
  }
}

function setData(ds: DataSet): void {
  state.data = ds;
  clearIdentify();
  for (const [id, key] of [['col-t', 't'], ['col-u', 'u'], ['col-y', 'y']] as const) {
    const sel = $(id) as HTMLSelectElement;
    sel.innerHTML = '';
    for (const c of ds.columns) {
      const o = document.createElement('option');
      o.value = o.textContent = c;
      sel.appendChild(o);
    }
    sel.value = columnOf(ds, ds[key], key);
  }
  $('data-info').innerHTML = '';
  const b = document.createElement('strong');
  b.textContent = ds.name;
  $('data-info').append(b, ` — ${ds.samples} samples, Ts = ${fmt(ds.Ts)} s` +
    (ds.decimated ? `, drawn at ${ds.signals.t.length} points` : ''));
  $('data-info').classList.remove('muted');
  const yName = ($('col-y') as HTMLSelectElement).value || ds.y;
  const uName = ($('col-u') as HTMLSelectElement).value || ds.u;
  dataPlot.draw({
    title: 'Data: ' + ds.name,
    ylabel: yName,
    y2label: uName,
    series: [
      { label: 'output ' + yName, color: COLORS[0] },
      { label: 'input ' + uName, color: COLORS[1], scale: 'y2' },
    ],
  }, [ds.signals.t, ds.signals.y, ds.signals.u]);
  ($('identify') as HTMLButtonElement).disabled = false;
  ($('export-report') as HTMLButtonElement).disabled = false;
  $('identify-state').textContent = '';
  document.body.dataset.data = ds.id;
}

// The header name of the column a spec names: the name itself, the name
// without its unit ("y" for "y [N]"), or a 0-based index.
function columnOf(ds: DataSet, spec: string | undefined, key: 't' | 'u' | 'y'): string {
  const cols = ds.columns;
  if (spec !== undefined && spec !== null) {
    if (cols.includes(spec)) return spec;
    const bare = (c: string) => c.replace(/\s*[\[(].*[\])]\s*$/, '').trim();
    const byBare = cols.find((c) => bare(c) === spec);
    if (byBare) return byBare;
    if (/^\d+$/.test(spec) && Number(spec) < cols.length) return cols[Number(spec)];
  }
  return cols[{ t: 0, u: 1, y: 2 }[key]] ?? cols[0] ?? '';
}

function onColumnsChange(): void {
  const src = state.dataSource;
  if (!src) return;
  if (src.path) void openFile(src.path, columnChoice());
  else if (src.file) void uploadFile(src.file, columnChoice());
}

// ---------------------------------------------------------------------------
// (2) Identification
// ---------------------------------------------------------------------------
const identifyPlot = new TimePlot($('identify-plot'));

function buildMethods(): void {
  const box = $('methods');
  for (const m of METHODS) {
    const label = document.createElement('label');
    const cb = document.createElement('input');
    cb.type = 'checkbox';
    cb.name = 'method';
    cb.value = m;
    cb.checked = DEFAULT_METHODS.includes(m);
    label.append(cb, ' ' + m);
    box.appendChild(label);
  }
}

function checkedMethods(): string[] {
  return [...document.querySelectorAll<HTMLInputElement>('#methods input[name=method]:checked')].map((c) => c.value);
}

function preprocessing(): { detrend?: string; window?: string } {
  const out: { detrend?: string; window?: string } = {};
  const d = ($('detrend') as HTMLSelectElement).value;
  if (d !== 'none') out.detrend = d;
  const w = ($('window') as HTMLInputElement).value.trim();
  if (w) out.window = w;
  return out;
}

async function identify(): Promise<void> {
  clearError('identify-error');
  if (!state.data) {
    showError('identify-error', new Error('open a data file first'));
    return;
  }
  const methods = checkedMethods();
  if (methods.length === 0) {
    showError('identify-error', new Error('tick at least one method'));
    return;
  }
  const btn = $('identify') as HTMLButtonElement;
  btn.disabled = true;
  $('identify-state').textContent = 'identifying with ' + methods.join(', ') + ' …';
  const t0 = performance.now();
  try {
    const res = await call<IdentifyResult>('POST', '/api/identify', {
      body: { data: state.data.id, methods, ...preprocessing(), ...(state.validation ? { validation: state.validation.id } : {}) },
    });
    state.identify = res;
    state.identifyMethods = methods;
    state.identifyDetrend = ($('detrend') as HTMLSelectElement).value;
    const ms = performance.now() - t0;
    const nfail = Array.isArray(res.failures) ? res.failures.length : 0;
    $('identify-state').textContent = `${res.models.length} models in ${(ms / 1000).toFixed(2)} s` +
      (nfail ? `, ${nfail} failed` : '');
    const warn = $('identify-failures');
    warn.innerHTML = '';
    for (const f of (res.failures ?? []) as any[]) {
      const li = document.createElement('li');
      const b = document.createElement('strong');
      b.textContent = f.method ?? '';
      li.append(b, ' ' + (f.message ?? f.reason ?? f.error ?? (f.method ? '' : JSON.stringify(f))));
      warn.appendChild(li);
    }
    const warnings = appendWarnings(warn, res.warnings);
    warn.hidden = nfail === 0 && warnings === 0;
    clearStale(IDENTIFY_RESULTS);
    showIdentify(res);
  } catch (e) {
    $('identify-state').textContent = '';
    showError('identify-error', e);
    markStale(IDENTIFY_RESULTS, 'the last identification failed: these are the results of an earlier one');
  } finally {
    btn.disabled = false;
  }
}

function modelEntry(method: string): ModelEntry | undefined {
  return state.identify?.model_file?.models?.find((m) => m.method === method);
}

function paramText(entry: ModelEntry | undefined): string {
  if (!entry || !entry.params) return '';
  return Object.entries(entry.params)
    .map(([k, v]) => `${k}=${fmt(v)}`)
    .join(', ');
}

function flagName(f: string | { flag: string; reason?: string }): string {
  return typeof f === 'string' ? f : f.flag;
}

function showIdentify(res: IdentifyResult): void {
  const tbody = $('fit-table').querySelector('tbody')!;
  tbody.innerHTML = '';
  const best = res.best ?? res.models[0]?.method ?? '';
  for (const m of res.models) {
    const tr = document.createElement('tr');
    tr.dataset.method = m.method;
    const entry = modelEntry(m.method);
    const use = document.createElement('td');
    const radio = document.createElement('input');
    radio.type = 'radio';
    radio.name = 'model';
    radio.value = m.method;
    radio.checked = m.method === best;
    radio.addEventListener('change', () => chooseModel(m.method));
    use.appendChild(radio);
    const method = document.createElement('td');
    method.className = 'method';
    method.textContent = m.method + (m.method === best ? ' (best)' : '');
    const structure = document.createElement('td');
    structure.textContent = m.structure ?? entry?.structure ?? '';
    const fit = document.createElement('td');
    fit.className = 'fit';
    fit.dataset.value = String(m.fit_percent);
    fit.textContent = typeof m.fit_percent === 'number' ? m.fit_percent.toFixed(2) : String(m.fit_percent);
    const flags = document.createElement('td');
    flags.className = 'flags';
    const detailed = entry?.flags ?? [];
    for (const f of m.flags ?? []) {
      const span = document.createElement('span');
      span.className = 'flag';
      span.textContent = flagName(f);
      const d = detailed.find((x) => flagName(x) === flagName(f));
      const reason = typeof f === 'object' ? f.reason : d && typeof d === 'object' ? d.reason : undefined;
      if (reason) span.title = reason;
      flags.appendChild(span);
    }
    const params = document.createElement('td');
    params.className = 'params';
    params.textContent = paramText(entry);
    tr.append(use, method, structure, fit, flags, params);
    tr.addEventListener('click', (ev) => {
      if ((ev.target as HTMLElement).tagName !== 'INPUT') {
        radio.checked = true;
        chooseModel(m.method);
      }
    });
    tbody.appendChild(tr);
  }
  drawResponses(res);
  ($('export-model') as HTMLButtonElement).disabled = !res.model_file;
  chooseModel(best);
}

// The models' responses to the data's input over the data.
function drawResponses(res: IdentifyResult): void {
  const r = res.responses;
  if (r && Array.isArray(r.t) && state.data) {
    const all = res.models.map((m) => m.method).filter((m) => Array.isArray(r[m]));
    // Responses that diverge (non-finite, or beyond 10 x the data's range
    // from it) would stretch the shared axis: listed, drawn on demand.
    const ys = state.data.signals.y.filter((v) => Number.isFinite(v));
    const lo = Math.min(...ys), hi = Math.max(...ys);
    const span = Math.max(hi - lo, 1e-12);
    state.excluded = all.filter((m) => (r[m] as (number | null)[]).some(
      (v) => v === null || !Number.isFinite(v) || v > hi + 10 * span || v < lo - 10 * span));
    const showAll = ($('identify-show-all') as HTMLInputElement).checked;
    const methods = showAll ? all : all.filter((m) => !state.excluded.includes(m));
    $('identify-excluded').hidden = state.excluded.length === 0;
    $('identify-excluded-list').textContent = state.excluded.length
      ? `not drawn (their responses diverge from the data by more than 10 x its range): ${state.excluded.join(', ')}. `
      : '';
    // the responses are in the coordinates of the identification: the data
    // drawn with them is detrended the same way (over the window's points)
    const detrend = state.identifyDetrend;
    const ydata = detrendData(interp(state.data.signals.t, state.data.signals.y, r.t), r.t, detrend);
    identifyPlot.draw({
      title: 'Model responses to the data\'s input',
      ylabel: (($('col-y') as HTMLSelectElement).value || state.data.y) + (detrend !== 'none' ? ` (detrended, ${detrend})` : ''),
      series: [
        { label: detrend !== 'none' ? 'data (detrended)' : 'data', color: '#495057', width: 2.5 },
        ...methods.map((m, i) => ({ label: m, color: COLORS[(i + 1) % COLORS.length], dash: i % 2 ? [6, 3] : undefined })),
      ],
    }, [r.t, ydata, ...methods.map((m) => r[m])]);
  }
}

function detrendData(y: (number | null)[], t: number[], how: string): (number | null)[] {
  if (how !== 'constant' && how !== 'linear') return y;
  let n = 0, st = 0, sy = 0, stt = 0, sty = 0;
  y.forEach((v, i) => {
    if (v === null) return;
    n++; st += t[i]; sy += v; stt += t[i] * t[i]; sty += t[i] * v;
  });
  if (n === 0) return y;
  let a = sy / n, b = 0;
  if (how === 'linear' && n > 1) {
    const d = n * stt - st * st;
    if (d !== 0) {
      b = (n * sty - st * sy) / d;
      a = (sy - b * st) / n;
    }
  }
  return y.map((v, i) => (v === null ? null : v - a - b * t[i]));
}

function chooseModel(method: string): void {
  state.model = method;
  void loadViews(method);
  $('ctl-model').textContent = method || 'none';
  for (const tr of $('fit-table').querySelectorAll<HTMLTableRowElement>('tbody tr')) {
    const on = tr.dataset.method === method;
    tr.classList.toggle('chosen', on);
    const radio = tr.querySelector<HTMLInputElement>('input[type=radio]');
    if (radio) radio.checked = on;
  }
  scheduleControl();
}

// ---------------------------------------------------------------------------
// Validation data and the views of the chosen model (POST /api/model/views)
// ---------------------------------------------------------------------------
const viewsPlot = new TimePlot($('views-plot'));
const viewsPlot2 = new TimePlot($('views-plot2'));

function fillValidationChoices(files: string[]): void {
  const sel = $('validation-file') as HTMLSelectElement;
  const keep = sel.value;
  sel.innerHTML = '';
  const none = document.createElement('option');
  none.value = '';
  none.textContent = 'none';
  sel.appendChild(none);
  for (const f of files) {
    const o = document.createElement('option');
    o.value = o.textContent = f;
    sel.appendChild(o);
  }
  if (keep && ![...sel.options].some((o) => o.value === keep)) {
    const o = document.createElement('option');
    o.value = o.textContent = keep;
    sel.appendChild(o);
  }
  sel.value = keep;
}

async function chooseValidation(path: string): Promise<void> {
  clearError('identify-error');
  if (!path) {
    state.validation = null;
    $('validation-info').textContent = '';
  } else {
    try {
      const cols = columnChoice();
      state.validation = await call<DataSet>('POST', '/api/data/open', { body: { path, ...cols, validation: true } });
      $('validation-info').textContent = `${state.validation.samples} samples: the models are ranked on it (held-out fit) at the next Identify`;
    } catch (e) {
      state.validation = null;
      ($('validation-file') as HTMLSelectElement).value = '';
      showError('identify-error', e);
    }
  }
  if (state.model) void loadViews(state.model);
}

let viewsSeq = 0;
async function loadViews(method: string): Promise<void> {
  const entry = modelEntry(method);
  if (!entry || !state.data) return;
  const seq = ++viewsSeq;
  try {
    const res = await call('POST', '/api/model/views', {
      body: { model: entry, data: state.data.id, ...(state.validation ? { validation: state.validation.id } : {}) },
    });
    if (seq !== viewsSeq) return;
    state.views = res;
    $('views').hidden = false;
    $('views-model').textContent = method;
    drawView();
  } catch (e) {
    if (seq !== viewsSeq) return;
    showError('identify-error', e);
  }
}

function drawView(): void {
  const v = state.views;
  if (!v) return;
  for (const b of $('views-tabs').querySelectorAll<HTMLButtonElement>('button'))
    b.classList.toggle('primary', b.dataset.view === state.view);
  viewsPlot2.destroy();
  const yName = (($('col-y') as HTMLSelectElement).value || state.data?.y) ?? 'y';
  const info: string[] = [];
  if (state.view === 'data') {
    const e = v.estimation;
    if (e?.t) {
      viewsPlot.draw({ title: 'Estimation data and the model (from an estimated initial state)', ylabel: yName,
        series: [{ label: 'data', color: '#495057', width: 2 }, { label: v.method, color: COLORS[0] }] }, [e.t, e.y, e.y_model]);
      info.push(`fit on the estimation data ${fmt(e.fit_percent)} %`);
    }
    const val = v.validation;
    if (val?.t) {
      viewsPlot2.draw({ title: 'Validation data and the model', ylabel: yName,
        series: [{ label: 'validation data', color: '#495057', width: 2 }, { label: v.method, color: COLORS[2] }] }, [val.t, val.y, val.y_model]);
      info.push(`on the validation data ${fmt(val.fit_percent)} %`);
    } else {
      info.push('choose validation data above to see the model on data it was not fitted to');
    }
  } else if (state.view === 'step') {
    if (v.step?.t) {
      viewsPlot.draw({ title: 'Unit step response' + (v.linear_part ? ' of the linear part' : ''), ylabel: 'y per unit input',
        series: [{ label: v.method, color: COLORS[0], width: 2 }] }, [v.step.t, v.step.y]);
    } else info.push('no step response: ' + (v.step?.error ?? ''));
  } else if (state.view === 'bode') {
    if (v.bode?.omega) {
      viewsPlot.draw({ title: 'Bode: magnitude' + (v.linear_part ? ' of the linear part' : ''), ylabel: '|G| [dB]', xlabel: 'ω [rad/s]', xlog: true,
        series: [{ label: v.method, color: COLORS[0], width: 2 }] }, [v.bode.omega, v.bode.magnitude_db]);
      viewsPlot2.draw({ title: 'Bode: phase', ylabel: 'phase [°]', xlabel: 'ω [rad/s]', xlog: true,
        series: [{ label: v.method, color: COLORS[1], width: 2 }] }, [v.bode.omega, v.bode.phase_deg]);
    } else info.push('no Bode diagram: ' + (v.bode?.error ?? ''));
  } else {
    const src = v.validation ?? v.estimation;
    const r = src?.residuals;
    if (r?.auto_lags) {
      const band = (n: number, s: number) => new Array(n).fill(s * r.bound);
      viewsPlot.draw({ title: `Residual autocorrelation (${v.validation ? 'validation' : 'estimation'} data)`, ylabel: 'r_ee(k) / r_ee(0)', xlabel: 'lag k [samples]',
        series: [{ label: 'autocorrelation', color: COLORS[0], width: 2 },
                 { label: `${Math.round(100 * r.confidence)} % band`, color: '#e03131', dash: [6, 4], width: 1 },
                 { label: '', color: '#e03131', dash: [6, 4], width: 1 }] },
        [r.auto_lags, r.autocorr, band(r.auto_lags.length, 1), band(r.auto_lags.length, -1)]);
      viewsPlot2.draw({ title: 'Cross-correlation of the residuals with the input', ylabel: 'r_ue(k)', xlabel: 'lag k [samples]',
        series: [{ label: 'cross-correlation', color: COLORS[1], width: 2 },
                 { label: `${Math.round(100 * r.confidence)} % band`, color: '#e03131', dash: [6, 4], width: 1 },
                 { label: '', color: '#e03131', dash: [6, 4], width: 1 }] },
        [r.cross_lags, r.crosscorr, band(r.cross_lags.length, 1), band(r.cross_lags.length, -1)]);
      info.push(`${fmt(100 * r.auto_outside, 3)} % of the autocorrelation lags and ${fmt(100 * r.cross_outside, 3)} % of the cross-correlation lags lie outside the band` +
        (r.auto_outside > 0.05 ? ': the residuals are not white (the model leaves dynamics unexplained)' : ''));
    } else {
      viewsPlot.destroy();
      info.push('no residual analysis: ' + (r?.error ?? 'no data'));
    }
  }
  $('views-info').textContent = info.join('; ');
}

// ---------------------------------------------------------------------------
// (3) Controller: any change re-runs /api/control (debounced, latest wins)
// ---------------------------------------------------------------------------
const controlPlot = new TimePlot($('control-plot'));
const controlUPlot = new TimePlot($('control-u-plot'));

/** A closed loop's set point and output over its controller output, as both
 *  the design (section 3) and the live run (section 4) show it. */
type Trace = { t: number[]; r: number[]; y: number[]; u: number[] };

// Axis names with units: the IPA twin's force and duty, else the data's
// column names (which carry their units, e.g. "y [N]").
function loopLabels(plant: string): { y: string; u: string } {
  if (plant.startsWith('ipa-position')) return { y: 'position x [m]', u: 'duty u [%]' };
  if (plant.startsWith('ipa')) return { y: 'force F [N]', u: 'duty u [%]' };
  const y = (document.getElementById('col-y') as HTMLSelectElement | null)?.value || state.data?.y || 'y';
  const u = (document.getElementById('col-u') as HTMLSelectElement | null)?.value || state.data?.u || 'u';
  return { y: 'output ' + y, u: 'input ' + u };
}

// The limits drawn as lines: the input range asked for (else the IPA's
// 0..100 %), and the soft output bounds when set.
function loopLimits(plant: string): { u: [number, number] | null; y: [number, number] | null } {
  const num = (id: string) => {
    const v = (document.getElementById(id) as HTMLInputElement | null)?.value.trim() ?? '';
    return v === '' ? NaN : Number(v);
  };
  let uMin = num('u-min'), uMax = num('u-max');
  if (plant.startsWith('ipa')) {
    if (Number.isNaN(uMin)) uMin = 0;
    if (Number.isNaN(uMax)) uMax = 100;
  }
  const yMin = num('y-min'), yMax = num('y-max');
  return {
    u: Number.isNaN(uMin) && Number.isNaN(uMax) ? null : [uMin, uMax],
    y: Number.isNaN(yMin) && Number.isNaN(yMax) ? null : [yMin, yMax],
  };
}

/** A closed loop's set point and output over its controller output, as both
 *  the design (section 3) and the live run (section 4) show it, with units,
 *  the limits as red dashed lines and, when given, a baseline design dashed. */
function drawLoop(yPlot: TimePlot, uPlot: TimePlot, title: string, tr: Trace,
                  plant = 'ipa', baseline: { label: string; trace: Trace } | null = null): void {
  const labels = loopLabels(plant);
  const limits = loopLimits(plant);
  const flat = (v: number) => tr.t.map(() => (Number.isFinite(v) ? v : null));
  const base = baseline ? interpTrace(baseline.trace, tr.t) : null;
  const ySeries: any[] = [
    { label: 'set point r', color: '#495057', dash: [5, 4] },
    { label: 'output y', color: COLORS[0], width: 2 },
  ];
  const yData: (number | null)[][] = [tr.t, tr.r, tr.y];
  if (base) {
    ySeries.push({ label: 'baseline y (' + baseline!.label + ')', color: '#868e96', dash: [3, 3] });
    yData.push(base.y);
  }
  if (limits.y) {
    ySeries.push({ label: 'y min', color: '#e03131', dash: [8, 4], width: 1 }, { label: 'y max', color: '#e03131', dash: [8, 4], width: 1 });
    yData.push(flat(limits.y[0]), flat(limits.y[1]));
  }
  yPlot.draw({ title, ylabel: labels.y, series: ySeries }, yData);
  const uSeries: any[] = [{ label: 'input u', color: COLORS[1] }];
  const uData: (number | null)[][] = [tr.t, tr.u];
  if (base) {
    uSeries.push({ label: 'baseline u', color: '#868e96', dash: [3, 3] });
    uData.push(base.u);
  }
  if (limits.u) {
    uSeries.push({ label: 'u min', color: '#e03131', dash: [8, 4], width: 1 }, { label: 'u max', color: '#e03131', dash: [8, 4], width: 1 });
    uData.push(flat(limits.u[0]), flat(limits.u[1]));
  }
  uPlot.draw({ title: 'Controller output', ylabel: labels.u, height: 180, series: uSeries }, uData);
}

function interpTrace(b: Trace, t: number[]): { y: (number | null)[]; u: (number | null)[] } {
  return { y: interp(b.t, b.y, t), u: interp(b.t, b.u, t) };
}

let explicitFromSliders = false; // the sliders hold values the user set
let responseTimeSet = false;

// lambda: the rule's value exactly until the (logarithmic) slider moves
let lambdaExact: number | null = null;
function lambdaValue(): number {
  if (lambdaExact !== null) return lambdaExact;
  const v = Math.pow(10, Number(($('lambda') as HTMLInputElement).value));
  return Number(v.toPrecision(3));
}

function controllerBody(): Record<string, unknown> {
  const body: Record<string, unknown> = {};
  const ctl = ($('ctl') as HTMLSelectElement).value;
  const rule = ($('rule') as HTMLSelectElement).value;
  body.controller = ctl;
  body.rule = rule;
  if (rule === 'explicit') {
    body.P = Number(($('P') as HTMLInputElement).value);
    body.M = Number(($('M') as HTMLInputElement).value);
    body.lambda = lambdaValue();
  }
  if (rule === 'auto' && responseTimeSet) body.response_time = Number(($('rt') as HTMLInputElement).value);
  const entry = modelEntry(state.model);
  if (entry) body.model = entry;
  const plant = ($('plant') as HTMLSelectElement).value;
  if (plant !== 'model') body.plant = plant;
  body.Ts = Number(($('Ts') as HTMLInputElement).value);
  body.setpoint = ($('setpoint') as HTMLInputElement).value.trim();
  body.duration = Number(($('duration') as HTMLInputElement).value);
  const load = ($('load-step') as HTMLInputElement).value.trim();
  if (load) body.load_step = load;
  for (const [id, key] of [['u-min', 'u_min'], ['u-max', 'u_max']]) {
    const v = ($(id) as HTMLInputElement).value.trim();
    if (v !== '') body[key] = Number(v);
  }
  if (ctl === 'pid') {
    for (const key of ['Kc', 'Ti', 'Td']) {
      const v = ($(key) as HTMLInputElement).value.trim();
      if (v !== '') body[key] = key === 'Ti' && /^inf/i.test(v) ? 1e300 : Number(v);
    }
  }
  if (ctl === 'mpc' || ctl === 'dmc') {
    for (const [id, key] of [['du-max', 'du_max'], ['y-min', 'y_min'], ['y-max', 'y_max']]) {
      const v = ($(id) as HTMLInputElement).value.trim();
      if (v !== '') body[key] = Number(v);
    }
  }
  if (ctl === 'mpc') body.disturbance = ($('disturbance') as HTMLSelectElement).value;
  if (ctl === 'dmc' && ($('constrained') as HTMLInputElement).checked) body.constrained = true;
  return body;
}

let pendingSince = 0; // performance.now() of the first change not yet drawn
let controlSeq = 0;
let controlAbort: AbortController | null = null;
const debouncedControl = debounce(() => void runControl(), 30);
const debouncedTune = debounce(() => void runTune(), 150);
const controlTimerPending = () => debouncedControl.pending();

function scheduleControl(): void {
  if (!state.model) return;
  if (!pendingSince) pendingSince = performance.now();
  state.controlIdle = false;
  $('control-state').textContent = 'simulating …';
  debouncedControl();
  debouncedTune();
}

// Appends one "warning: ..." item per string of `warnings` (an answer's
// "warnings", if an array) to the list; how many.
function appendWarnings(list: HTMLElement, warnings: unknown): number {
  const items = Array.isArray(warnings) ? warnings : [];
  for (const w of items) {
    const li = document.createElement('li');
    const b = document.createElement('strong');
    b.textContent = 'warning:';
    li.append(b, ' ' + String(w));
    list.appendChild(li);
  }
  return items.length;
}

async function runControl(): Promise<void> {
  const seq = ++controlSeq;
  controlAbort?.abort();
  const abort = new AbortController();
  controlAbort = abort;
  const body = controllerBody();
  const t0 = performance.now();
  try {
    const res = await call('POST', '/api/control', { body, signal: abort.signal });
    if (seq !== controlSeq) return; // a newer request wins
    const t1 = performance.now();
    clearError('control-error');
    state.control = res;
    clearStale(CONTROL_RESULTS);
    drawControl(res);
    const t2 = performance.now();
    const latency = t2 - (pendingSince || t0);
    pendingSince = 0;
    state.controlLatency.push(latency);
    state.controlTimings.push({ server: t1 - t0, draw: t2 - t1 });
    state.controlCount++;
    document.body.dataset.controlCount = String(state.controlCount);
    state.controlIdle = !controlTimerPending();
    $('control-state').textContent =
      `${res.controller ?? ''} on ${res.plant ?? ''}: server ${(t1 - t0).toFixed(0)} ms, ` +
      `drawn ${(t2 - t1).toFixed(0)} ms, change to redraw ${latency.toFixed(0)} ms`;
    // A set-point beyond what the model reaches within the input limits.
    const warnList = $('control-warnings');
    warnList.innerHTML = '';
    warnList.hidden = appendWarnings(warnList, res.warnings) === 0;
  } catch (e) {
    if (seq !== controlSeq) return;
    pendingSince = 0;
    state.controlIdle = !controlTimerPending();
    $('control-state').textContent = '';
    showError('control-error', e);
    markStale(CONTROL_RESULTS, 'the last change failed: these are the results of the settings before it');
  }
}

function drawControl(res: any): void {
  const tr = res.trace;
  const plant = ($('plant') as HTMLSelectElement).value;
  if (tr && Array.isArray(tr.t)) {
    drawLoop(controlPlot, controlUPlot, 'Closed loop: set point and output', tr,
             plant === 'model' ? '' : plant, state.baseline);
  }
  const tbody = $('metrics').querySelector('tbody')!;
  tbody.innerHTML = '';
  const base = state.baseline?.metrics;
  if (base) {
    const head = document.createElement('tr');
    for (const text of ['', 'this design', 'baseline']) {
      const th = document.createElement('th');
      th.textContent = text;
      head.appendChild(th);
    }
    tbody.appendChild(head);
  }
  for (const [key, label] of METRIC_KEYS) {
    if (!(key in res)) continue;
    const row = document.createElement('tr');
    const th = document.createElement('td');
    th.textContent = label;
    const td = document.createElement('td');
    td.className = 'numcol';
    td.dataset.key = key;
    td.dataset.value = JSON.stringify(res[key]);
    td.textContent = fmt(res[key]);
    row.append(th, td);
    if (base) {
      const b = document.createElement('td');
      b.className = 'numcol baseline';
      b.textContent = fmt(base[key]);
      row.appendChild(b);
    }
    tbody.appendChild(row);
  }
  // A PID with a rule is described by its gains (the tune review is the
  // horizons' and applies to the rule auto only).
  if (($('ctl') as HTMLSelectElement).value === 'pid' && ($('rule') as HTMLSelectElement).value !== 'auto') {
    const g = res.settings ?? {};
    $('review').textContent = [
      `pid, ${g.rule === 'explicit' ? 'gains given (the others by SIMC)' : 'rule ' + (g.rule ?? 'simc')}`,
      `Kc = ${fmt(g.Kc)}, Ti = ${g.Ti === null || g.Ti === undefined ? 'inf (no integral action)' : fmt(g.Ti) + ' s'}, Td = ${fmt(g.Td)} s`,
      res.controller ?? '',
    ].join('\n');
    $('review').classList.remove('muted');
  }
  // The rule's choice shown on the sliders (unless the user set them)
  const s = res.settings ?? {};
  if (!explicitFromSliders) {
    if (typeof s.P === 'number') setSlider('P', s.P, String(s.P));
    if (typeof s.M === 'number') setSlider('M', s.M, String(s.M));
    if (typeof s.lambda === 'number' && s.lambda > 0) setSlider('lambda', Math.log10(s.lambda), fmt(s.lambda, 3));
    else if (typeof s.lambda === 'number') $('lambda-out').textContent = fmt(s.lambda, 3);
    if (typeof s.lambda === 'number') lambdaExact = s.lambda;
  }
}

function setSlider(id: string, value: number, text: string): void {
  ($(id) as HTMLInputElement).value = String(value);
  $(id + '-out').textContent = text;
}

async function runTune(): Promise<void> {
  if (!state.model) return;
  if (($('ctl') as HTMLSelectElement).value === 'pid' && ($('rule') as HTMLSelectElement).value !== 'auto') return;
  const body = controllerBody();
  const seq = ++tuneSeq;
  try {
    const res = await call('POST', '/api/tune', { body });
    if (seq !== tuneSeq) return;
    state.tune = res;
    $('review').textContent = reviewText(res);
    $('review').classList.remove('muted');
  } catch (e) {
    if (seq !== tuneSeq) return;
    $('review').textContent = 'no design review: ' + (e as Error).message;
    $('review').classList.add('muted');
  }
}
let tuneSeq = 0;

function reviewText(t: any): string {
  const lines: string[] = [];
  const head = [t.controller, t.rule && `rule ${t.rule}`].filter(Boolean).join(', ');
  if (head) lines.push(head);
  const hz = ['P', 'M', 'lambda'].filter((k) => t[k] !== undefined).map((k) => `${k} = ${fmt(t[k])}`);
  if (hz.length) lines.push(hz.join(', '));
  if (t.formula) lines.push(t.formula);
  if (t.fopdt) lines.push(`FOPDT: K = ${fmt(t.fopdt.K)}, tau = ${fmt(t.fopdt.tau)} s, theta = ${fmt(t.fopdt.theta)} s`);
  if (t.predicted) {
    const p = t.predicted;
    lines.push(`predicted: rise ${fmt(p.rise_time)} s, overshoot ${fmt(p.overshoot_percent)} %, settling ${fmt(p.settling_time)} s`);
  }
  if (Array.isArray(t.review)) {
    lines.push('');
    for (const r of t.review) lines.push(`${r.status === 'ok' ? '✓' : r.status === 'warning' ? '!' : '✗'} ${r.check}: ${r.message}`);
  }
  if (Array.isArray(t.robustness)) {
    lines.push('');
    for (const r of t.robustness)
      lines.push(`${r.pass ? '✓' : '✗'} ${r.case}: rise ${fmt(r.rise_time)} s, overshoot ${fmt(r.overshoot_percent)} %`);
  }
  if (t.message) lines.push('', t.message);
  return lines.join('\n') || JSON.stringify(t, null, 2);
}

// gpc has no rule auto; pid has no horizons (its rules give Kc, Ti, Td)
function controllerChoices(): void {
  const ctl = ($('ctl') as HTMLSelectElement).value;
  const rule = $('rule') as HTMLSelectElement;
  const auto = rule.querySelector<HTMLOptionElement>('option[value=auto]')!;
  auto.disabled = ctl === 'gpc';
  if (ctl === 'gpc' && rule.value === 'auto') rule.value = 'shridhar-cooper';
  for (const id of ['P', 'M', 'lambda']) ($(id) as HTMLInputElement).disabled = ctl === 'pid';
  ($('rt') as HTMLInputElement).disabled = ctl === 'gpc';
  $('pid-gains').hidden = ctl !== 'pid';
  $('mpc-limits').hidden = ctl !== 'mpc' && ctl !== 'dmc';
  ($('disturbance') as HTMLSelectElement).disabled = ctl !== 'mpc';
  ($('constrained') as HTMLInputElement).disabled = ctl !== 'dmc';
}

function bindController(): void {
  $('ctl').addEventListener('change', controllerChoices);
  controllerChoices();
  for (const id of ['ctl', 'rule', 'plant']) $(id).addEventListener('change', () => {
    if (id === 'rule') explicitFromSliders = ($('rule') as HTMLSelectElement).value === 'explicit' && explicitFromSliders;
    scheduleControl();
  });
  for (const id of ['setpoint', 'duration', 'Ts', 'load-step', 'u-min', 'u-max', 'du-max', 'y-min', 'y-max']) $(id).addEventListener('input', scheduleControl);
  for (const id of ['disturbance', 'constrained']) $(id).addEventListener('change', scheduleControl);
  for (const id of ['Kc', 'Ti', 'Td']) {
    $(id).addEventListener('input', () => {
      // explicit gains replace the rule's; the rule auto designs them itself
      if (($('rule') as HTMLSelectElement).value === 'auto') ($('rule') as HTMLSelectElement).value = 'shridhar-cooper';
      scheduleControl();
    });
  }
  $('baseline-keep').addEventListener('click', () => {
    const res = state.control;
    if (!res?.trace) return showError('control-error', new Error('no closed loop to keep yet'));
    state.baseline = { label: res.controller ?? 'baseline', trace: res.trace, metrics: res };
    $('baseline-info').textContent = 'baseline: ' + state.baseline.label;
    ($('baseline-clear') as HTMLButtonElement).disabled = false;
    drawControl(res);
  });
  $('baseline-clear').addEventListener('click', () => {
    state.baseline = null;
    $('baseline-info').textContent = '';
    ($('baseline-clear') as HTMLButtonElement).disabled = true;
    if (state.control) drawControl(state.control);
  });
  for (const id of ['P', 'M', 'lambda']) {
    $(id).addEventListener('input', () => {
      if (state.model) pendingSince = performance.now();
      explicitFromSliders = true;
      if (id === 'lambda') lambdaExact = null;
      ($('rule') as HTMLSelectElement).value = 'explicit';
      $('P-out').textContent = ($('P') as HTMLInputElement).value;
      $('M-out').textContent = ($('M') as HTMLInputElement).value;
      $('lambda-out').textContent = fmt(lambdaValue(), 3);
      scheduleControl();
    });
  }
  $('rt').addEventListener('input', () => {
    if (state.model) pendingSince = performance.now();
    responseTimeSet = true;
    ($('rule') as HTMLSelectElement).value = 'auto';
    explicitFromSliders = false;
    $('rt-out').textContent = ($('rt') as HTMLInputElement).value + ' s';
    scheduleControl();
  });
  $('rt-default').addEventListener('click', () => {
    responseTimeSet = false;
    $('rt-out').textContent = 'default';
    scheduleControl();
  });
}

// ---------------------------------------------------------------------------
// (4) Run: real time with live plots over a WebSocket
// ---------------------------------------------------------------------------
const runPlot = new TimePlot($('run-plot'));
const runUPlot = new TimePlot($('run-u-plot'));
const MAX_LIVE_POINTS = 4000;
let live = { t: [] as number[], r: [] as number[], y: [] as number[], u: [] as number[], stride: 1, skip: 0 };
let liveFrame = 0;
let ws: WebSocket | null = null;
let statusTimer: number | undefined;
let runT0 = 0;

function setRunState(s: string, text: string): void {
  state.run.state = s;
  const el = $('run-state');
  el.dataset.state = s;
  el.textContent = text;
  const running = s === 'running' || s === 'starting';
  ($('run-start') as HTMLButtonElement).disabled = running;
  ($('run-stop') as HTMLButtonElement).disabled = !running;
}

function runStatusText(): string {
  const el = ((performance.now() - runT0) / 1000).toFixed(1);
  return `${state.run.state}: ${state.run.samples} samples, ${el} s, ${state.run.frames} frames, ${live.t.length} points drawn`;
}

function appendLive(m: { t: number[]; r?: number[]; y: number[]; u: number[] }): void {
  for (let i = 0; i < m.t.length; i++) {
    state.run.samples++;
    if (live.skip++ % live.stride !== 0) continue;
    live.t.push(m.t[i]);
    live.r.push(m.r ? m.r[i] : NaN);
    live.y.push(m.y[i]);
    live.u.push(m.u[i]);
  }
  // Decimate by 2 when the plot holds too many points
  if (live.t.length > MAX_LIVE_POINTS) {
    const half = (a: number[]) => a.filter((_, i) => i % 2 === 0);
    live = { t: half(live.t), r: half(live.r), y: half(live.y), u: half(live.u), stride: live.stride * 2, skip: 1 };
  }
  state.run.points = live.t.length;
  if (!liveFrame) liveFrame = requestAnimationFrame(drawLive);
}

function drawLive(): void {
  liveFrame = 0;
  const io = ($('io') as HTMLInputElement).value.trim() || 'sim';
  const plant = ($('plant') as HTMLSelectElement).value;
  drawLoop(runPlot, runUPlot, 'Real-time run: set point and output', live,
           io === 'sim' && plant !== 'model' ? plant : io.startsWith('udp') ? 'ipa' : '');
  if (state.run.state === 'running') $('run-state').textContent = runStatusText();
}

async function startRun(): Promise<void> {
  clearError('run-error');
  if (!state.model) {
    showError('run-error', new Error('identify and choose a model first'));
    return;
  }
  const body = controllerBody();
  body.duration = Number(($('run-duration') as HTMLInputElement).value);
  body.io = ($('io') as HTMLInputElement).value.trim() || 'sim';
  const maxOverruns = ($('max-overruns') as HTMLInputElement).value.trim();
  if (maxOverruns !== '') body.max_overruns = Number(maxOverruns);
  live = { t: [], r: [], y: [], u: [], stride: 1, skip: 0 };
  state.run = { state: 'starting', samples: 0, points: 0, frames: 0, summary: null };
  $('run-details').hidden = true;
  setRunState('starting', 'starting …');
  try {
    await call('POST', '/api/run/start', { body });
  } catch (e) {
    setRunState('failed', 'failed to start');
    showError('run-error', e);
    return;
  }
  runT0 = performance.now();
  setRunState('running', 'running: waiting for the first samples …');
  attachRun();
}

// The live stream and the status poll of the run going on (started by this
// page, or found running when the page loaded: the stream sends it from its
// first sample).
function attachRun(): void {
  ws = new WebSocket(streamUrl('/api/run/stream'));
  ws.onmessage = (ev) => {
    let m: any;
    try {
      m = JSON.parse(String(ev.data));
    } catch {
      return;
    }
    state.run.frames++;
    if (m.done) {
      // a Stop's end can reach the stream before the Stop's answer: the
      // summary's termination says how the run ended
      const t = m.summary?.termination;
      finishRun(m.summary ?? null, t === 'stopped' ? 'stopped' : t === 'failure' ? 'failed' : 'finished');
      return;
    }
    if (Array.isArray(m.t)) appendLive(m);
  };
  ws.onerror = () => showError('run-error', new Error('the live stream (WebSocket /api/run/stream) failed'));
  ws.onclose = () => {
    ws = null;
    if (state.run.state === 'running') void pollStatus(true);
  };
  clearInterval(statusTimer);
  statusTimer = window.setInterval(() => void pollStatus(false), 500);
}

// A page loaded (or reloaded) takes over the server's session: the last data
// set opened and its last identification (the chosen model is the best one).
async function restoreSession(): Promise<void> {
  try {
    const s = await call('GET', '/api/session');
    if (!s.data) return;
    state.dataSource = { path: s.data.name };
    setData(s.data);
    const req = s.identify_request;
    if (s.identify && req) {
      const methods: string[] = Array.isArray(req.methods) ? req.methods : String(req.methods ?? '').split(',');
      for (const cb of document.querySelectorAll<HTMLInputElement>('#methods input[name=method]'))
        cb.checked = methods.includes(cb.value);
      if (req.detrend) ($('detrend') as HTMLSelectElement).value = req.detrend;
      if (req.window) ($('window') as HTMLInputElement).value = req.window;
      state.identify = s.identify;
      state.identifyMethods = methods;
      state.identifyDetrend = req.detrend ?? 'none';
      $('identify-state').textContent = `${s.identify.models.length} models (restored from the session)`;
      showIdentify(s.identify);
    }
    document.body.dataset.restored = '1';
  } catch (e) {
    // a server without sessions (web/tests/mock_server.mjs) answers 404
    if (!(e instanceof ApiError && e.status === 404)) showError('data-error', e);
  }
}

// A page loaded (or reloaded) while a run goes on takes it over: the live
// plot from the run's first sample and a Stop that works.
async function findRunningRun(): Promise<void> {
  try {
    const s = await call('GET', '/api/run/status');
    if (s.state !== 'running') return;
    live = { t: [], r: [], y: [], u: [], stride: 1, skip: 0 };
    state.run = { state: 'running', samples: 0, points: 0, frames: 0, summary: null };
    runT0 = performance.now() - 1000 * (typeof s.elapsed === 'number' ? s.elapsed : 0);
    setRunState('running', 'running (started before this page was loaded) …');
    document.body.dataset.attached = '1';
    attachRun();
  } catch (e) {
    showError('run-error', e);
  }
}

async function pollStatus(final: boolean): Promise<void> {
  try {
    const s = await call('GET', '/api/run/status');
    if (s.state && s.state !== 'running' && state.run.state === 'running') {
      // the stream may still deliver its last frames: give it a moment
      if (!final && ws) return;
      finishRun(s.summary ?? null, s.state);
    } else if (state.run.state === 'running') {
      $('run-state').textContent = runStatusText() + (typeof s.elapsed === 'number' ? `, server ${s.samples} samples` : '');
    }
  } catch (e) {
    if (final) finishRun(null, 'failed');
  }
}

function finishRun(summary: any, how: string): void {
  clearInterval(statusTimer);
  statusTimer = undefined;
  if (ws && ws.readyState === WebSocket.OPEN) ws.close();
  if (liveFrame) {
    cancelAnimationFrame(liveFrame);
    liveFrame = 0;
  }
  drawLive();
  state.run.summary = summary;
  const parts = [`${how}: ${state.run.samples} samples streamed`];
  if (summary) {
    if (summary.samples !== undefined) parts.push(`${summary.samples} samples run`);
    if (summary.wall_time !== undefined) parts.push(`${fmt(summary.wall_time)} s wall`);
    if (summary.jitter_p99_us !== undefined) parts.push(`jitter p99 ${fmt(summary.jitter_p99_us)} µs`);
    if (summary.compute_p99_us !== undefined) parts.push(`compute p99 ${fmt(summary.compute_p99_us)} µs`);
    if (summary.overruns !== undefined) parts.push(`${summary.overruns} overruns`);
    $('run-summary').textContent = JSON.stringify(summary, null, 2);
    $('run-details').hidden = false;
  }
  setRunState(how === 'running' ? 'finished' : how, parts.join(', '));
}

async function stopRun(): Promise<void> {
  try {
    const summary = await call('POST', '/api/run/stop');
    if (state.run.state === 'running') finishRun(summary?.summary ?? summary ?? null, 'stopped');
  } catch (e) {
    // 409: no run to stop (it ended meanwhile): the status says how
    if (e instanceof ApiError && e.status === 409) void pollStatus(true);
    else showError('run-error', e);
  }
}

// ---------------------------------------------------------------------------
// (5) Export
// ---------------------------------------------------------------------------
function bindExport(): void {
  $('export-model').addEventListener('click', () => {
    clearError('export-error');
    const mf = state.identify?.model_file;
    if (!mf) return showError('export-error', new Error('identify models first'));
    download(new Blob([JSON.stringify(mf, null, 2) + '\n'], { type: 'application/json' }), 'models.json');
  });
  $('export-controller').addEventListener('click', async () => {
    clearError('export-error');
    try {
      const body = controllerBody();
      body.io = ($('io') as HTMLInputElement).value.trim() || 'sim';
      body.duration = Number(($('run-duration') as HTMLInputElement).value);
      const text = await call<string>('POST', '/api/export/controller', { body, as: 'text' });
      download(new Blob([text], { type: 'text/plain' }), 'controller.toml');
    } catch (e) {
      showError('export-error', e);
    }
  });
  ($('export-log') as HTMLAnchorElement).href = withToken('/api/run/log');
  $('export-report').addEventListener('click', async () => {
    clearError('export-error');
    if (!state.data) return showError('export-error', new Error('open a data file first'));
    const methods = state.identifyMethods.length ? state.identifyMethods : checkedMethods();
    try {
      const blob = await call<Blob>('POST', '/api/export/report', {
        body: { data: state.data.id, methods }, as: 'blob',
      });
      download(new Blob([blob], { type: 'text/html' }), 'report.html');
    } catch (e) {
      showError('export-error', e);
    }
  });
}

// ---------------------------------------------------------------------------
// (6) Commission: POST /api/commission, the library's Commission() on the plant
// ---------------------------------------------------------------------------
const commissionExpPlot = new TimePlot($('cm-exp-plot'));
const commissionPlot = new TimePlot($('cm-plot'));
const commissionUPlot = new TimePlot($('cm-u-plot'));

// Only the fields filled in are sent: an empty one leaves the plant's own
// default (a positioning drive is specified 2 % / 1 s, a force loop 5 % /
// 0.5 s), where Number('') would send 0.
function commissionBody(): Record<string, unknown> {
  const num = (id: string) => ($(id) as HTMLInputElement).value.trim();
  const body: Record<string, unknown> = {
    plant: num('cm-plant') || 'ipa',
    controller: ($('cm-ctl') as HTMLSelectElement).value,
  };
  for (const [id, key] of [['cm-budget', 'budget'], ['cm-overshoot', 'overshoot'],
                           ['cm-settling', 'settling']]) {
    if (num(id) !== '') body[key] = Number(num(id));
  }
  if (num('cm-lo') !== '' && num('cm-hi') !== '') body.range = [Number(num('cm-lo')), Number(num('cm-hi'))];
  if (num('cm-dir') !== '') body.dir = num('cm-dir');
  return body;
}

function cell(text: string, numeric = false): HTMLTableCellElement {
  const td = document.createElement('td');
  td.textContent = text;
  if (numeric) td.className = 'numcol';
  return td;
}

function drawCommission(res: any): void {
  $('cm-result').hidden = false;
  const msg = $('cm-message');
  msg.textContent = `${res.termination}: ${res.message}`;
  msg.dataset.passed = String(!!res.passed);
  const models = $('cm-models').querySelector('tbody')!;
  models.innerHTML = '';
  for (const m of res.models ?? []) {
    const tr = document.createElement('tr');
    tr.append(cell(m.method), cell(fmt(m.fit_percent), true), cell(fmt(m.validation_fit_percent), true),
              cell(m.method === res.chosen_model ? 'chosen' : ''));
    models.appendChild(tr);
  }
  $('cm-chosen').textContent = res.chosen_reason ? 'chosen: ' + res.chosen_reason : '';
  const attempts = $('cm-attempts').querySelector('tbody')!;
  attempts.innerHTML = '';
  for (const a of res.attempts ?? []) {
    const tr = document.createElement('tr');
    tr.append(cell(fmt(a.aggressiveness), true), cell(fmt(a.overshoot_percent), true),
              cell(fmt(a.settling_time), true), cell(fmt(a.iae), true),
              cell(a.passed ? 'pass' : 'fail: ' + (a.failures ?? []).join('; ')));
    attempts.appendChild(tr);
  }
  const limits = $('cm-limits');
  limits.innerHTML = '';
  for (const [prefix, list] of [['limit', res.limits], ['try', res.suggestions]] as [string, string[]][]) {
    for (const l of list ?? []) {
      const li = document.createElement('li');
      li.textContent = `${prefix}: ${l}`;
      limits.appendChild(li);
    }
  }
  const ex = res.experiment_trace;
  if (ex && Array.isArray(ex.t)) {
    commissionExpPlot.draw({
      title: 'Experiment: input and output',
      ylabel: 'output y',
      y2label: 'input u',
      series: [
        { label: 'output y', color: COLORS[0] },
        { label: 'input u', color: COLORS[1], scale: 'y2' },
      ],
    }, [ex.t, ex.y, ex.u]);
  }
  if (res.trace && Array.isArray(res.trace.t)) {
    drawLoop(commissionPlot, commissionUPlot, 'Verification on the plant: set point and output', res.trace);
  }
  const files = res.files?.written ?? [];
  $('cm-files').textContent = res.directory
    ? `${files.length} files in ${res.directory} (under the root)`
    : `${files.length} files in the app's temporary folder`;
}

async function startCommission(): Promise<void> {
  clearError('cm-error');
  const button = $('cm-start') as HTMLButtonElement;
  button.disabled = true;
  const st = $('cm-state');
  st.textContent = 'commissioning … (experiment, identification, design, verification)';
  st.dataset.state = 'running';
  $('cm-result').hidden = true;
  const t0 = performance.now();
  try {
    const res = await call('POST', '/api/commission', { body: commissionBody() });
    state.commission = res;
    drawCommission(res);
    st.textContent = `${res.termination} in ${((performance.now() - t0) / 1000).toFixed(1)} s ` +
      `(plant time ${fmt(res.plant_time)} s)`;
    st.dataset.state = res.termination;
  } catch (e) {
    st.textContent = 'failed';
    st.dataset.state = 'failure';
    showError('cm-error', e);
  } finally {
    button.disabled = false;
  }
}

function bindCommission(): void {
  $('cm-start').addEventListener('click', () => void startCommission());
  $('cm-toml').addEventListener('click', () => {
    const text = state.commission?.controller_toml;
    if (!text) return showError('cm-error', new Error('no controller was designed'));
    download(new Blob([text], { type: 'text/plain' }), 'controller.toml');
  });
}

// ---------------------------------------------------------------------------
async function main(): Promise<void> {
  buildMethods();
  bindController();
  bindExport();
  bindCommission();
  $('files-up').addEventListener('click', () => void listFiles(state.dir.split('/').slice(0, -1).join('/')));
  $('files-refresh').addEventListener('click', () => void listFiles(state.dir));
  ($('upload') as HTMLInputElement).addEventListener('change', (ev) => {
    const f = (ev.target as HTMLInputElement).files?.[0];
    if (f) void uploadFile(f);
  });
  for (const id of ['col-t', 'col-u', 'col-y']) $(id).addEventListener('change', onColumnsChange);
  $('identify').addEventListener('click', () => void identify());
  ($('validation-file') as HTMLSelectElement).addEventListener('change', (ev) =>
    void chooseValidation((ev.target as HTMLSelectElement).value));
  for (const b of $('views-tabs').querySelectorAll<HTMLButtonElement>('button')) {
    b.addEventListener('click', () => {
      state.view = b.dataset.view ?? 'data';
      drawView();
    });
  }
  $('identify-show-all').addEventListener('change', () => {
    if (state.identify) drawResponses(state.identify);
  });
  ($('identify') as HTMLButtonElement).disabled = true;
  $('run-start').addEventListener('click', () => void startRun());
  $('run-stop').addEventListener('click', () => void stopRun());
  if (!new URLSearchParams(location.search).get('token')) {
    showError('global-error', new Error('the address has no ?token=…: open the address that `pneumid app` printed'));
  }
  try {
    const v = await call('GET', '/api/version');
    $('version').textContent = 'pneumid ' + (v.version ?? '') + (v.root ? ' — root ' + v.root : '');
  } catch (e) {
    showError('global-error', e);
  }
  await listFiles('');
  await restoreSession();
  await findRunningRun();
  document.body.dataset.ready = '1';
}

void main();

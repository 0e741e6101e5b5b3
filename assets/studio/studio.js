// gaitfit studio page. Everything is drawn here on 2-D canvases (no library); every number
// shown comes from the server (controls, ranges, units, motion, steps, curves, data).
'use strict';
(function () {
  const $ = (id) => document.getElementById(id);
  const LOCK_RULES = {
    run: 'RUNNER (§3.1.1): v = sl·sf always holds (eq. 1). A locked parameter stays fixed when ' +
      'another moves; the unlocked ones follow eqs. 2–5. Locking two of v, sl, sf fixes the third.',
    walk: 'KLAW (§3): a locked parameter is one you give; the moved one is given too, and eq. 1 ' +
      '(sl = k·sf·h, v = sl·sf) completes the rest. Nothing locked: the natural walk at the speed.',
    generalize: 'Ko–Badler: v = sl·sf; the step length is the generalization\'s parameter, the ' +
      'cadence the prototype\'s scaled to the body unless you lock or move it.',
  };
  // Public state for the browser test (read through the DevTools protocol).
  const studio = window.studio = {
    ready: false, seq: 0, errors: 0, lastError: '', timing: null, motionDigest: 0,
  };
  let catalog = null;
  let generator = 'run';
  let good = null;          // last successful answer
  let values = {};          // resolved values of the last success, keyed by control key
  let locks = new Set();
  let flightFromHeight = false;
  let dataPoints = {};
  let dataNotes = [];       // data tables that could not be read (said once per answer)
  const queue = [];         // pending edits: {key, value}
  let busy = false;

  // ---------------------------------------------------------------- requests
  function body(edit) {
    const v = Object.assign({}, values);
    if (edit && edit.key === 'height_m' && good) {
      // Attributes left at their defaults take the new body's defaults (lengths scale with it).
      for (const c of good.controls) if (c.group === 'attribute' && c.value === c.default) delete v[c.key];
    }
    if (edit && edit.key) v[edit.key] = edit.value;
    return {
      generator,
      values: v,
      locks: Array.from(locks),
      changed: edit && edit.key ? edit.key : null,
      flight_from_height: flightFromHeight,
      relations: $('relations').value,
      seconds: Number($('seconds').value) || 10,
      from_rest: generator === 'walk' && $('from-rest').checked,
      stop: generator !== 'generalize' && $('stop').checked,
      schedule: readSchedule(),
    };
  }

  function edit(key, value, t0) {
    const last = queue[queue.length - 1];
    if (last && last.key === key) { last.value = value; last.t0 = Math.min(last.t0, t0); }
    else queue.push({ key, value, t0 });
    pump();
  }

  async function pump() {
    if (busy) return;
    busy = true;
    try {
      while (queue.length) await generate(queue.shift());
    } finally { busy = false; }
  }

  async function generate(e) {
    const t0 = e.t0 || performance.now();
    const req = body(e);
    let res, json;
    const tSend = performance.now();
    try {
      res = await fetch('/api/generate', {
        method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(req),
      });
      const text = await res.text();
      var tGot = performance.now();
      json = JSON.parse(text);
    } catch (err) {
      showError('The studio server did not answer: ' + err.message);
      return;
    }
    const tParsed = performance.now();
    if (!json.ok) {
      showError(json.error || ('error ' + res.status));
      markInvalid(e.key);
      renderValues();
      return;
    }
    apply(json);
    const tDrawn = performance.now();
    studio.timing = {
      generate_ms: json.timing.generate_ms,
      server_ms: json.timing.server_ms,
      fetch_ms: tGot - tSend,
      parse_ms: tParsed - tGot,
      draw_ms: tDrawn - tParsed,
      total_ms: tDrawn - t0,
      frames: json.figure.frames,
      bytes: 0,
    };
    $('timing').textContent = 'generated ' + fmt(json.timing.generate_ms, 1) + ' ms · request ' +
      fmt(tGot - tSend, 1) + ' ms · parse ' + fmt(tParsed - tGot, 1) + ' ms · draw ' +
      fmt(tDrawn - tParsed, 1) + ' ms · move→drawn ' + fmt(tDrawn - t0, 1) + ' ms';
    studio.seq += 1;
  }

  function showError(msg) {
    studio.errors += 1;
    studio.lastError = msg;
    const el = $('error');
    el.textContent = msg;
    el.hidden = false;
  }

  function clearError() { $('error').hidden = true; $('error').textContent = ''; studio.lastError = ''; }

  function markInvalid(key) {
    if (!key) return;
    const n = document.querySelector('[data-key="' + key + '"] input[type=number]');
    if (n) n.classList.add('invalid');
  }

  // ---------------------------------------------------------------- controls
  function fmt(x, d) { return (x === null || x === undefined || !isFinite(x)) ? '–' : Number(x).toFixed(d); }
  function decimals(step) { return Math.max(0, Math.min(6, Math.ceil(-Math.log10(step) - 1e-9))); }

  function buildControls(controls) {
    for (const id of ['params', 'body', 'attributes']) $(id).textContent = '';
    for (const c of controls) {
      const box = c.group === 'parameter' ? $('params') : c.group === 'body' ? $('body') : $('attributes');
      const row = document.createElement('div');
      row.className = 'ctl';
      row.dataset.key = c.key;
      const label = document.createElement('label');
      label.textContent = c.label;
      label.title = c.label + ' (' + c.unit + '): ' + c.doc;
      row.appendChild(label);
      let input;
      if (c.choices.length) {
        input = document.createElement('select');
        for (const [v, name] of c.choices) {
          const o = document.createElement('option');
          o.value = String(v); o.textContent = name;
          input.appendChild(o);
        }
        input.addEventListener('change', () => edit(c.key, Number(input.value), performance.now()));
        row.appendChild(input);
        row.appendChild(document.createElement('span'));
      } else {
        input = document.createElement('input');
        input.type = 'range';
        input.setAttribute('aria-label', c.label);
        const num = document.createElement('input');
        num.type = 'number'; num.step = 'any';
        num.setAttribute('aria-label', c.label + ' (' + c.unit + ')');
        input.addEventListener('input', () => {
          num.value = fmt(Number(input.value), decimals(Number(input.step)));
          edit(c.key, Number(input.value), performance.now());
        });
        num.addEventListener('change', () => {
          const v = Number(num.value);
          if (num.value.trim() === '' || !isFinite(v)) {
            showError(c.label + ': "' + num.value + '" is not a number');
            num.classList.add('invalid');
            return;
          }
          edit(c.key, v, performance.now());
        });
        row.appendChild(input);
        row.appendChild(num);
      }
      if (c.lockable) {
        const lock = document.createElement('input');
        lock.type = 'checkbox'; lock.className = 'lock';
        lock.title = 'lock: keep ' + c.label + ' fixed while another parameter moves';
        lock.setAttribute('aria-label', 'lock ' + c.label);
        lock.checked = locks.has(c.key);
        lock.addEventListener('change', () => {
          if (lock.checked) locks.add(c.key); else locks.delete(c.key);
          row.classList.toggle('locked', lock.checked);
        });
        row.appendChild(lock);
      } else row.appendChild(document.createElement('span'));
      const unit = document.createElement('span');
      unit.className = 'unit';
      unit.textContent = c.unit;
      unit.title = c.doc;
      row.appendChild(unit);
      box.appendChild(row);
    }
  }

  function renderValues() {
    if (!good) return;
    for (const c of good.controls) {
      const row = document.querySelector('.ctl[data-key="' + c.key + '"]');
      if (!row) continue;
      const sel = row.querySelector('select');
      if (sel) { sel.value = String(c.value); continue; }
      const r = row.querySelector('input[type=range]');
      const n = row.querySelector('input[type=number]');
      const d = decimals(c.step);
      r.min = c.min; r.max = c.max; r.step = c.step;
      if (document.activeElement !== r) r.value = c.value;
      if (document.activeElement !== n || !n.classList.contains('invalid')) n.value = fmt(c.value, Math.max(d, 2));
      row.classList.toggle('locked', locks.has(c.key));
    }
  }

  function apply(json) {
    const rebuild = !good || good.generator !== json.generator ||
      good.controls.length !== json.controls.length;
    good = json;
    values = {};
    for (const c of json.controls) if (isFinite(c.value) && c.value !== null) values[c.key] = c.value;
    flightFromHeight = json.flight_from_height;
    if (rebuild) buildControls(json.controls);
    document.querySelectorAll('input.invalid').forEach((x) => x.classList.remove('invalid'));
    renderValues();
    clearError();
    $('relations-source').textContent = json.relations_source;
    renderNotes(json.notes);
    renderSteps(json.steps);
    setFigure(json.figure);
    renderPlots(json.plots);
  }

  function renderNotes(notes) {
    const el = $('notes');
    el.textContent = '';
    for (const n of notes.concat(dataNotes)) {
      const d = document.createElement('div');
      d.textContent = 'note: ' + n;
      el.appendChild(d);
    }
  }

  function renderSteps(steps) {
    const t = $('steps');
    t.textContent = '';
    const run = generator === 'run';
    const cols = [['#', null], ['side', null], ['t s', 'time_s', 2], ['km/h', 'speed_km_per_h', 2],
      ['sl m', 'step_length_m', 3], ['steps/min', 'step_freq_steps_per_min', 1],
      ['stance s', 'stance_time_s', 3],
      run ? ['flight s', 'flight_time_s', 3] : ['t_ds %', 'double_support_pct_cycle', 1]];
    const head = t.insertRow();
    for (const [name] of cols) { const th = document.createElement('th'); th.textContent = name; head.appendChild(th); }
    steps.forEach((s, i) => {
      const r = t.insertRow();
      for (const [, key, d] of cols) {
        const td = r.insertCell();
        td.textContent = key === null ? (td.cellIndex === 0 ? String(i) : s.side) : fmt(s[key], d);
      }
    });
  }

  // ---------------------------------------------------------------- schedule
  function addRow(r) {
    r = r || {};
    const tr = $('schedule').tBodies[0].insertRow();
    const cell = (cls) => { const td = tr.insertCell(); if (cls) td.className = cls; return td; };
    const num = (name, v, cls) => {
      const i = document.createElement('input');
      i.type = 'number'; i.step = 'any'; i.name = name; i.value = v === undefined || v === null ? '' : v;
      i.addEventListener('change', scheduleChanged);
      cell(cls).appendChild(i);
    };
    num('step', r.step === undefined ? 4 : r.step);
    num('speed_km_per_h', r.speed_km_per_h);
    num('step_length_m', r.step_length_m);
    num('step_freq_steps_per_min', r.step_freq_steps_per_min);
    num('flight_height_m', r.flight_height_m, 'run-only');
    const sel = document.createElement('select');
    sel.name = 'action';
    for (const a of ['run', 'stop']) { const o = document.createElement('option'); o.value = a; o.textContent = a === 'run' ? 'change' : 'stop'; sel.appendChild(o); }
    sel.value = r.action || 'run';
    sel.addEventListener('change', scheduleChanged);
    cell().appendChild(sel);
    const del = document.createElement('button');
    del.type = 'button'; del.textContent = '✕'; del.title = 'remove this change';
    del.addEventListener('click', () => { tr.remove(); scheduleChanged(); });
    cell().appendChild(del);
  }

  function readSchedule() {
    const rows = [];
    for (const tr of $('schedule').tBodies[0].rows) {
      const r = {};
      for (const i of tr.querySelectorAll('input')) {
        if (i.value.trim() === '') continue;
        if (i.name === 'flight_height_m' && generator !== 'run') continue;
        r[i.name] = Number(i.value);
      }
      r.action = tr.querySelector('select').value;
      if (r.step === undefined) r.step = 0;
      rows.push(r);
    }
    return rows;
  }

  function scheduleChanged() { edit('', null, performance.now()); }

  // ---------------------------------------------------------------- figure
  let fig = null;            // {fps, frames, xyz, contacts, bones, left, events, n}
  let t = 0, playing = true, lastTick = null;
  const cam = { yaw: -0.9, pitch: 0.25, dist: 4.2 };

  function setFigure(f) {
    const n = f.landmarks.length;
    const prints = [];
    const heel = { left: f.landmarks.indexOf('l_heel'), right: f.landmarks.indexOf('r_heel') };
    for (const e of f.events) {
      if (e.kind !== 'heel_strike') continue;
      const i = Math.min(f.frames - 1, Math.max(0, Math.round(e.t * f.fps)));
      const k = (i * n + heel[e.side]) * 3;
      prints.push({ x: f.xyz[k], z: f.xyz[k + 2], side: e.side });
    }
    let headMax = 0;
    const head = f.landmarks.indexOf('vertex');
    for (let i = 0; i < Math.min(f.frames, 50); i++) headMax = Math.max(headMax, f.xyz[(i * n + head) * 3 + 1]);
    fig = Object.assign({}, f, { n, prints, height: headMax || 1.8 });
    let digest = 0;
    for (let i = 0; i < f.xyz.length; i += 97) digest += f.xyz[i];
    studio.motionDigest = digest;
    const s = $('scrub');
    s.max = String(Math.max(0, f.frames - 1));
    if (t * f.fps > f.frames - 1) t = 0;
    draw();
  }

  function frameIndex() { return fig ? Math.min(fig.frames - 1, Math.max(0, Math.floor(t * fig.fps))) : 0; }
  function P(i, j) { const k = (i * fig.n + j) * 3; return [fig.xyz[k], fig.xyz[k + 1], fig.xyz[k + 2]]; }

  const COL = { left: '#2f6fd0', right: '#d2452f', mid: '#333' };
  function boneColor(a, b) { return fig.left[a] && fig.left[b] ? COL.left : (fig.landmarks[a].startsWith('r_') || fig.landmarks[b].startsWith('r_')) ? COL.right : COL.mid; }
  function footOf(side) {
    const p = side === 'left' ? 'l_' : 'r_';
    return ['heel', 'ball', 'toe', 'ankle'].map((x) => fig.landmarks.indexOf(p + x));
  }

  function drawSagittal(i) {
    const c = $('sagittal'), g = c.getContext('2d');
    const W = c.width, H = c.height;
    g.clearRect(0, 0, W, H);
    const s = H * 0.72 / fig.height;
    const pelvis = P(i, 0);
    const gy = H * 0.88;
    const X = (x) => W / 2 + (x - pelvis[0]) * s, Y = (y) => gy - y * s;
    g.strokeStyle = '#999'; g.lineWidth = 1;
    g.beginPath(); g.moveTo(0, gy); g.lineTo(W, gy); g.stroke();
    g.fillStyle = '#888'; g.font = '10px system-ui';
    const span = W / s / 2 + 1;
    for (let m = Math.floor(pelvis[0] - span); m <= pelvis[0] + span; m += 0.5) {
      g.beginPath(); g.moveTo(X(m), gy); g.lineTo(X(m), gy + (m % 1 === 0 ? 8 : 4)); g.stroke();
      if (m % 1 === 0) g.fillText(m + ' m', X(m) + 2, gy + 16);
    }
    for (const p of fig.prints) {
      g.fillStyle = p.side === 'left' ? COL.left : COL.right;
      g.beginPath(); g.moveTo(X(p.x), gy); g.lineTo(X(p.x) - 4, gy + 6); g.lineTo(X(p.x) + 4, gy + 6); g.fill();
    }
    // Far side (left) first, drawn lighter.
    for (const pass of [true, false]) {
      for (const [a, b] of fig.bones) {
        if (fig.left[a] !== pass && fig.left[b] !== pass) continue;
        if (!pass && (fig.left[a] || fig.left[b])) continue;
        const pa = P(i, a), pb = P(i, b);
        g.strokeStyle = boneColor(a, b);
        g.globalAlpha = pass ? 0.55 : 1;
        g.lineWidth = 3;
        g.beginPath(); g.moveTo(X(pa[0]), Y(pa[1])); g.lineTo(X(pb[0]), Y(pb[1])); g.stroke();
      }
    }
    g.globalAlpha = 1;
    const head = P(i, fig.landmarks.indexOf('vertex')), neck = P(i, fig.landmarks.indexOf('neck'));
    const r = Math.max(4, Math.hypot(head[0] - neck[0], head[1] - neck[1]) * s * 0.32);
    g.strokeStyle = COL.mid; g.lineWidth = 2;
    g.beginPath(); g.arc(X(head[0]), Y(head[1]) + r, r, 0, 2 * Math.PI); g.stroke();
    ['left', 'right'].forEach((side, k) => {
      if (!fig.contacts[2 * i + k]) return;
      const [h, b, to] = footOf(side);
      const ph = P(i, h), pt = P(i, to), pb = P(i, b);
      g.strokeStyle = side === 'left' ? COL.left : COL.right;
      g.lineWidth = 7; g.globalAlpha = 0.45;
      g.beginPath(); g.moveTo(X(ph[0]), Y(ph[1])); g.lineTo(X(pb[0]), Y(pb[1])); g.lineTo(X(pt[0]), Y(pt[1])); g.stroke();
      g.globalAlpha = 1;
    });
    g.fillStyle = '#444'; g.font = '11px system-ui';
    const con = (k) => fig.contacts[2 * i + k] ? 'on' : 'off';
    g.fillText('left foot ' + con(0) + ' · right foot ' + con(1), 8, 14);
  }

  function drawOrbit(i) {
    const c = $('orbit'), g = c.getContext('2d');
    const W = c.width, H = c.height;
    g.clearRect(0, 0, W, H);
    const tgt = P(i, 0);
    tgt[1] = fig.height * 0.5;
    const cy = Math.cos(cam.yaw), sy = Math.sin(cam.yaw), cp = Math.cos(cam.pitch), sp = Math.sin(cam.pitch);
    // Camera basis: eye on a sphere around the target; y up.
    const eye = [tgt[0] + cam.dist * cp * cy, tgt[1] + cam.dist * sp, tgt[2] + cam.dist * cp * sy];
    const fwd = norm([tgt[0] - eye[0], tgt[1] - eye[1], tgt[2] - eye[2]]);
    const right = norm(cross(fwd, [0, 1, 0]));
    const up = cross(right, fwd);
    const f = H * 1.1;
    const proj = (p) => {
      const d = [p[0] - eye[0], p[1] - eye[1], p[2] - eye[2]];
      const z = dot(d, fwd);
      if (z < 0.05) return null;
      return [W / 2 + f * dot(d, right) / z, H / 2 - f * dot(d, up) / z];
    };
    const line = (a, b) => { const pa = proj(a), pb = proj(b); if (!pa || !pb) return; g.beginPath(); g.moveTo(pa[0], pa[1]); g.lineTo(pb[0], pb[1]); g.stroke(); };
    g.strokeStyle = '#ddd'; g.lineWidth = 1;
    const x0 = Math.floor(tgt[0]);
    for (let x = x0 - 5; x <= x0 + 5; x++) line([x, 0, -1.5], [x, 0, 1.5]);
    for (let z = -1.5; z <= 1.5; z += 0.5) line([x0 - 5, 0, z], [x0 + 5, 0, z]);
    for (const p of fig.prints) {
      const q = proj([p.x, 0, p.z]);
      if (!q) continue;
      g.fillStyle = p.side === 'left' ? COL.left : COL.right;
      g.globalAlpha = 0.6; g.beginPath(); g.arc(q[0], q[1], 3, 0, 2 * Math.PI); g.fill(); g.globalAlpha = 1;
    }
    for (const [a, b] of fig.bones) {
      g.strokeStyle = boneColor(a, b); g.lineWidth = 2.5;
      line(P(i, a), P(i, b));
    }
    ['left', 'right'].forEach((side, k) => {
      if (!fig.contacts[2 * i + k]) return;
      const [h, b, to] = footOf(side);
      g.strokeStyle = side === 'left' ? COL.left : COL.right; g.lineWidth = 6; g.globalAlpha = 0.45;
      line(P(i, h), P(i, b)); line(P(i, b), P(i, to)); g.globalAlpha = 1;
    });
  }
  function norm(v) { const l = Math.hypot(v[0], v[1], v[2]) || 1; return [v[0] / l, v[1] / l, v[2] / l]; }
  function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
  function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

  function draw() {
    if (!fig || !fig.frames) return;
    const i = frameIndex();
    drawSagittal(i);
    drawOrbit(i);
    $('scrub').value = String(i);
    $('clock').textContent = (i / fig.fps).toFixed(2) + ' s';
  }

  function tick(now) {
    if (lastTick !== null && playing && fig && fig.frames > 1) {
      t += (now - lastTick) / 1000 * Number($('rate').value);
      const dur = (fig.frames - 1) / fig.fps;
      if (t > dur) t = 0;
      draw();
    }
    lastTick = now;
    requestAnimationFrame(tick);
  }

  // ---------------------------------------------------------------- plots
  function renderPlots(plots) {
    const box = $('plots');
    box.textContent = '';
    for (const p of plots) {
      const title = document.createElement('div');
      title.className = 'plot-title';
      title.textContent = p.title;
      box.appendChild(title);
      const c = document.createElement('canvas');
      c.width = 356; c.height = 210;
      c.dataset.relation = p.id;
      box.appendChild(c);
      const note = document.createElement('p');
      note.className = 'plot-note';
      const d = dataPoints[p.id];
      note.textContent = p.note + (d ? ' · points: ' + d.source + ' (each subject at their own height)' : '');
      box.appendChild(note);
      drawPlot(c, p, d ? d.points : []);
    }
  }

  function drawPlot(c, p, data) {
    const g = c.getContext('2d');
    const W = c.width, H = c.height, L = 46, R = 8, T = 18, B = 30;
    let xs = [], ys = [];
    for (const cv of p.curves) for (const q of cv.points) if (q[0] !== null) { xs.push(q[0]); ys.push(q[1]); }
    if (p.point) { xs.push(p.point[0]); ys.push(p.point[1]); }
    const x0 = Math.min(...xs), x1 = Math.max(...xs);
    for (const q of data) if (q[0] >= x0 && q[0] <= x1) ys.push(q[1]);
    let y0 = Math.min(...ys), y1 = Math.max(...ys);
    if (!(y1 > y0)) { y0 -= 1; y1 += 1; }
    const pad = (y1 - y0) * 0.06; y0 -= pad; y1 += pad;
    const X = (x) => L + (x - x0) / (x1 - x0) * (W - L - R), Y = (y) => H - B - (y - y0) / (y1 - y0) * (H - T - B);
    g.clearRect(0, 0, W, H);
    g.strokeStyle = '#aaa'; g.lineWidth = 1; g.fillStyle = '#555'; g.font = '10px system-ui';
    g.strokeRect(L, T, W - L - R, H - T - B);
    for (const [v, isX] of ticks(x0, x1).map((v) => [v, true]).concat(ticks(y0, y1).map((v) => [v, false]))) {
      if (isX) { g.fillText(tickLabel(v), X(v) - 10, H - B + 12); g.beginPath(); g.moveTo(X(v), H - B); g.lineTo(X(v), H - B + 3); g.stroke(); }
      else { g.fillText(tickLabel(v), 2, Y(v) + 3); g.beginPath(); g.moveTo(L - 3, Y(v)); g.lineTo(L, Y(v)); g.stroke(); }
    }
    g.fillText(p.x.symbol + ' (' + p.x.unit + ')', W / 2 - 20, H - 4);
    g.fillText(p.y.symbol + ' (' + p.y.unit + ')', 4, 11);
    g.save(); g.beginPath(); g.rect(L, T, W - L - R, H - T - B); g.clip();
    g.fillStyle = '#bbb';
    for (const q of data) { g.beginPath(); g.arc(X(q[0]), Y(q[1]), 1.6, 0, 2 * Math.PI); g.fill(); }
    for (const cv of p.curves) {
      g.strokeStyle = cv.label === 'refit' ? '#1f77b4' : '#666';
      g.lineWidth = cv.in_use ? 2.6 : 1.2;
      g.setLineDash(cv.label === 'refit' ? [5, 3] : []);
      g.beginPath();
      let pen = false;
      for (const q of cv.points) {
        if (q[0] === null) { pen = false; continue; }
        if (pen) g.lineTo(X(q[0]), Y(q[1])); else g.moveTo(X(q[0]), Y(q[1]));
        pen = true;
      }
      g.stroke();
    }
    g.setLineDash([]);
    if (p.point) {
      g.fillStyle = '#e4572e';
      g.beginPath(); g.arc(X(p.point[0]), Y(p.point[1]), 5, 0, 2 * Math.PI); g.fill();
    }
    g.restore();
  }
  function ticks(a, b) {
    const step = Math.pow(10, Math.floor(Math.log10((b - a) / 4)));
    const k = (b - a) / step > 20 ? 5 : (b - a) / step > 8 ? 2 : 1;
    const out = [];
    for (let v = Math.ceil(a / (k * step)) * k * step; v <= b; v += k * step) out.push(v);
    return out;
  }
  function tickLabel(v) { return Math.abs(v) >= 100 ? v.toFixed(0) : Math.abs(v) >= 1 ? v.toFixed(1) : v.toPrecision(2); }

  // ---------------------------------------------------------------- exports
  async function download(name) {
    try {
      const res = await fetch('/api/export/' + name, {
        method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(body(null)),
      });
      const type = res.headers.get('Content-Type') || '';
      if (!res.ok || type.startsWith('application/json')) {
        let msg = 'export ' + name + ' failed (' + res.status + ')';
        try { msg = (await res.json()).error || msg; } catch (_) { /* keep the status */ }
        showError(msg);
        return;
      }
      const cd = res.headers.get('Content-Disposition') || '';
      const m = /filename="([^"]+)"/.exec(cd);
      const blob = await res.blob();
      const a = document.createElement('a');
      a.href = URL.createObjectURL(blob);
      a.download = m ? m[1] : 'gaitfit-' + generator + '.' + name;
      document.body.appendChild(a);
      a.click();
      a.remove();
      setTimeout(() => URL.revokeObjectURL(a.href), 10000);
      studio.downloads = (studio.downloads || 0) + 1;
    } catch (err) {
      showError('export ' + name + ': ' + err.message);
    }
  }

  // ---------------------------------------------------------------- wiring
  function setGenerator(name) {
    generator = name;
    values = {}; locks = new Set(); flightFromHeight = false; good = null;
    document.body.classList.toggle('not-run', name !== 'run');
    $('lock-rule').textContent = LOCK_RULES[name] || '';
    const g = catalog.generators.find((x) => x.name === name);
    $('from-rest').disabled = g.from_rest !== 'optional';
    $('from-rest').checked = g.from_rest.startsWith('always');
    $('stop').disabled = !g.stop;
    if (!g.stop) $('stop').checked = false;
    $('attributes-box').hidden = name === 'generalize';
    edit('', null, performance.now());
  }

  async function start() {
    try {
      catalog = await (await fetch('/api/catalog')).json();
      const d = await (await fetch('/api/data')).json();
      dataPoints = d.relations || {};
      dataNotes = d.notes || [];
    } catch (err) {
      showError('The studio server did not answer: ' + err.message);
      return;
    }
    const sel = $('generator');
    for (const g of catalog.generators) {
      const o = document.createElement('option');
      o.value = g.name; o.textContent = g.label;
      sel.appendChild(o);
    }
    sel.addEventListener('change', () => setGenerator(sel.value));
    for (const f of catalog.exports) {
      const b = document.createElement('button');
      b.type = 'button'; b.textContent = f.label; b.title = f.doc; b.dataset.format = f.name;
      b.addEventListener('click', () => download(f.name));
      $('exports').appendChild(b);
    }
    $('relations').addEventListener('change', () => edit('', null, performance.now()));
    $('seconds').addEventListener('change', () => edit('', null, performance.now()));
    $('from-rest').addEventListener('change', () => edit('', null, performance.now()));
    $('stop').addEventListener('change', () => edit('', null, performance.now()));
    $('add-row').addEventListener('click', () => { addRow(); scheduleChanged(); });
    $('reset-attributes').addEventListener('click', (ev) => {
      ev.preventDefault();
      for (const k of Object.keys(values)) if (k.startsWith('attr.')) delete values[k];
      edit('', null, performance.now());
    });
    $('play').addEventListener('click', () => { playing = !playing; $('play').textContent = playing ? 'pause' : 'play'; });
    $('scrub').addEventListener('input', () => { playing = false; $('play').textContent = 'play'; t = Number($('scrub').value) / (fig ? fig.fps : 1); draw(); });
    const orbit = $('orbit');
    let drag = null;
    orbit.addEventListener('pointerdown', (e) => { drag = [e.clientX, e.clientY]; orbit.setPointerCapture(e.pointerId); });
    orbit.addEventListener('pointerup', () => { drag = null; });
    orbit.addEventListener('pointermove', (e) => {
      if (!drag) return;
      cam.yaw += (e.clientX - drag[0]) * 0.01;
      cam.pitch = Math.max(-0.2, Math.min(1.4, cam.pitch + (e.clientY - drag[1]) * 0.01));
      drag = [e.clientX, e.clientY];
      draw();
    });
    orbit.addEventListener('wheel', (e) => { e.preventDefault(); cam.dist = Math.max(1.5, Math.min(15, cam.dist * Math.exp(e.deltaY * 0.001))); draw(); }, { passive: false });
    // A link can name the generator and a moment to show: ?generator=walk&t=3.2 (paused there).
    const q = new URLSearchParams(location.search);
    const first = catalog.generators.some((g) => g.name === q.get('generator')) ? q.get('generator') : catalog.generators[0].name;
    sel.value = first;
    setGenerator(first);
    await new Promise((r) => { const w = () => (busy || queue.length ? setTimeout(w, 20) : r()); w(); });
    if (q.has('t') && isFinite(Number(q.get('t')))) {
      t = Number(q.get('t')); playing = false; $('play').textContent = 'play'; draw();
    }
    studio.ready = true;
    requestAnimationFrame(tick);
  }

  studio.setGenerator = (name) => { $('generator').value = name; setGenerator(name); };
  studio.idle = () => !busy && queue.length === 0;
  document.addEventListener('DOMContentLoaded', start);
}());

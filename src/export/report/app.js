// report.html's script: sorts and filters the design table, and shows the selected design
// as a three.js view of its folding motion beside its crease pattern. Everything it draws
// comes from the JSON in #foldsynth-data (written by src/export/report/mod.rs); three.js
// is the global FoldsynthThree (vendor/three/three.bundle.min.js, inlined before this).
(function () {
  'use strict';

  const data = JSON.parse(document.getElementById('foldsynth-data').textContent);
  const table = document.getElementById('design-table');
  if (!table) return; // no feasible designs: nothing to show
  // Designs carried in full (card, geometry); every design is a row of the table.
  const byId = new Map(data.designs.map((d) => [d.id, d]));
  const tbody = table.tBodies[0];
  const heads = Array.from(table.tHead.rows[0].cells);
  const cols = heads.map((h) => ({ key: h.dataset.key, numeric: h.dataset.numeric === 'true', format: h.dataset.format }));
  const colIndex = new Map(cols.map((c, i) => [c.key, i]));
  // One entry per design: its values in column order, its search order, its <tr> once drawn.
  const rows = data.rows.map((v, i) => ({ id: String(v[0]), v: v, order: i, tr: null }));
  const rowById = new Map(rows.map((r) => [r.id, r]));
  const pageSize = data.page_size || 100;
  const state = { selected: null, frame: 0, playing: false, webgl: false, sort: null, page: 0, view: rows, filters: [] };
  // Read-only view of the page's state, for people poking around in the console.
  window.foldsynthReport = {
    get selected() { return state.selected; },
    get frame() { return state.frame; },
    get webgl() { return state.webgl; },
    get sort() { return state.sort; },
    get page() { return state.page; },
    get pages() { return pages(); },
    get shown() { return state.view.length; },
    get objects() { return view && view.names ? view.names() : []; },
  };

  // ---- table: cells -----------------------------------------------------------------------
  // The robustness margins (src/export/report/mod.rs MARGINS) and their labels.
  const MARGIN_NAMES = {
    rigid_margin: 'rigid margin',
    self_clearance: 'self clearance',
    arm_clearance: 'arm clearance',
    obstacle_clearance: 'obstacle clearance',
    min_feature: 'min feature',
  };
  // The text of a value as src/export/report/mod.rs writes it (Column::format).
  function cellText(x, format) {
    if (x === null || x === undefined) return '–';
    if (format === 'vertex') return 'v' + x;
    if (format === 'exp2') return x.toExponential(2).replace('e+', 'e');
    if (format === 'num') {
      if (x === 0) return '0';
      const a = Math.abs(x);
      if (a >= 1e-3 && a < 1e4) return x.toFixed(Math.max(0, 3 - Math.floor(Math.log10(a))));
      return x.toExponential(3).replace('e+', 'e');
    }
    return String(x);
  }

  // A margin's tooltip, from the card of a design carried in full.
  function cellTitle(r, key) {
    const d = byId.get(r.id);
    const m = d && d.robustness ? d.robustness[key] : null;
    if (!m || typeof m.value !== 'number') return null;
    let t = m.value + ' (setting ' + (typeof m.setting === 'number' ? m.setting : '–');
    if (typeof m.t === 'number') t += ', at t = ' + m.t.toFixed(4);
    if (m.where) t += ', ' + (Array.isArray(m.where) ? m.where.join(', ') : m.where);
    return t + ')';
  }

  function rowElement(r) {
    if (r.tr) return r.tr;
    const tr = document.createElement('tr');
    tr.dataset.id = r.id;
    tr.tabIndex = 0;
    cols.forEach((c, i) => {
      const td = document.createElement('td');
      const x = r.v[i];
      td.dataset.key = c.key;
      td.dataset.v = x === null || x === undefined ? '' : String(x);
      if (c.numeric) td.className = 'num';
      td.textContent = cellText(x, c.format);
      const title = c.key in MARGIN_NAMES ? cellTitle(r, c.key) : null;
      if (title) td.title = title;
      tr.appendChild(td);
    });
    tr.addEventListener('click', () => select(r.id));
    tr.addEventListener('keydown', (e) => {
      if (e.key === 'Enter') select(r.id);
    });
    r.tr = tr;
    return tr;
  }

  // ---- table: the page of rows shown --------------------------------------------------------
  const shownEl = document.getElementById('shown');
  const pageInfo = document.getElementById('page-info');
  const prevBtn = document.getElementById('page-prev');
  const nextBtn = document.getElementById('page-next');
  function pages() {
    return Math.max(1, Math.ceil(state.view.length / pageSize));
  }

  function render() {
    state.page = Math.min(Math.max(0, state.page), pages() - 1);
    const first = state.page * pageSize;
    const slice = state.view.slice(first, first + pageSize);
    tbody.replaceChildren(...slice.map(rowElement));
    for (const r of slice) r.tr.classList.toggle('selected', r.id === state.selected);
    shownEl.textContent = String(state.view.length);
    if (pageInfo) {
      pageInfo.textContent = state.view.length
        ? 'rows ' + (first + 1) + '–' + (first + slice.length) + ' of ' + state.view.length + ' (page ' + (state.page + 1) + ' of ' + pages() + ')'
        : 'no row matches';
    }
    if (prevBtn) prevBtn.disabled = state.page === 0;
    if (nextBtn) nextBtn.disabled = state.page >= pages() - 1;
  }
  if (prevBtn) prevBtn.addEventListener('click', () => { state.page -= 1; render(); });
  if (nextBtn) nextBtn.addEventListener('click', () => { state.page += 1; render(); });

  // ---- table: sorting -------------------------------------------------------------------
  // Stable: equal values keep the search's order; missing values go last either way.
  function compare(a, b, k, numeric, dir) {
    const x = a.v[k];
    const y = b.v[k];
    const nx = x === null || x === undefined;
    const ny = y === null || y === undefined;
    if (nx || ny) {
      if (nx && ny) return a.order - b.order;
      return nx ? 1 : -1;
    }
    const c = numeric ? x - y : String(x).localeCompare(String(y), 'en', { numeric: true });
    return c !== 0 ? dir * c : a.order - b.order;
  }

  function sorted(list) {
    if (!state.sort) return list.slice().sort((a, b) => a.order - b.order);
    const k = colIndex.get(state.sort.key);
    const numeric = cols[k].numeric;
    return list.slice().sort((a, b) => compare(a, b, k, numeric, state.sort.dir));
  }

  function sortBy(key, dir) {
    const th = heads.find((h) => h.dataset.key === key);
    if (!th) return;
    for (const h of heads) {
      h.setAttribute('aria-sort', h === th ? (dir > 0 ? 'ascending' : 'descending') : 'none');
    }
    state.sort = { key: key, dir: dir };
    state.view = sorted(state.view);
    state.page = 0;
    render();
  }

  for (const th of heads) {
    const go = () => {
      const same = state.sort && state.sort.key === th.dataset.key;
      sortBy(th.dataset.key, same ? -state.sort.dir : 1);
    };
    th.addEventListener('click', go);
    th.addEventListener('keydown', (e) => {
      if (e.key === 'Enter' || e.key === ' ') {
        e.preventDefault();
        go();
      }
    });
  }

  // ---- table: filtering -----------------------------------------------------------------
  const filters = Array.from(table.tHead.querySelectorAll('[data-filter]'));

  function passes(r, f) {
    const k = colIndex.get(f.key);
    const x = r.v[k];
    if (f.kind === 'text') return cellText(x, cols[k].format).toLowerCase().includes(f.value.toLowerCase());
    if (f.kind === 'choice') return cellText(x, cols[k].format) === f.value;
    if (x === null || x === undefined) return false;
    return f.kind === 'max' ? x <= f.limit : x >= f.limit;
  }

  function applyFilters() {
    const active = [];
    for (const el of filters) {
      const value = el.value.trim();
      el.classList.remove('invalid');
      if (value === '') continue;
      const f = { key: el.dataset.key, kind: el.dataset.filter, value: value };
      if (f.kind === 'max' || f.kind === 'min') {
        f.limit = Number(value);
        if (!Number.isFinite(f.limit)) {
          el.classList.add('invalid');
          el.title = 'not a number: ignored';
          continue;
        }
      }
      active.push(f);
    }
    state.filters = active;
    state.view = sorted(rows.filter((r) => active.every((f) => passes(r, f))));
    state.page = 0;
    render();
  }
  for (const el of filters) {
    el.addEventListener('input', applyFilters);
    el.addEventListener('change', applyFilters);
    el.addEventListener('click', (e) => e.stopPropagation());
  }

  // ---- the selected design ----------------------------------------------------------------
  function el(tag, attrs, text) {
    const e = document.createElement(tag);
    for (const k in attrs || {}) e.setAttribute(k, attrs[k]);
    if (text !== undefined) e.textContent = text;
    return e;
  }

  const views = document.querySelector('#detail .views');
  function select(id) {
    const r = rowById.get(id);
    if (!r) return;
    state.selected = id;
    for (const x of state.view.slice(state.page * pageSize, (state.page + 1) * pageSize)) {
      if (x.tr) x.tr.classList.toggle('selected', x.id === id);
    }
    const d = byId.get(id);
    if (views) views.hidden = !d;
    if (!d) {
      selectRowOnly(r);
      return;
    }
    const parts = [d.id, d.sequence];
    if (d.candidate !== null) parts.push('candidate ' + d.candidate);
    if (d.modes !== '–') parts.push(d.modes);
    document.getElementById('detail-title').textContent = parts.join(' — ');
    const facts = document.getElementById('detail-facts').tBodies[0];
    facts.replaceChildren();
    const robust = d.robustness ? robustnessFacts(d.robustness) : [];
    for (const [k, v] of [['id', d.id]].concat(d.facts, robust)) {
      const tr = el('tr');
      tr.appendChild(el('th', {}, k));
      tr.appendChild(el('td', {}, v));
      facts.appendChild(tr);
    }
    billTable(d.thick ? d.thick.bill : null);
    const files = document.getElementById('detail-files');
    files.replaceChildren();
    if (d.files.length) {
      files.appendChild(document.createTextNode('files (in the run\u2019s output folder): '));
      for (const [name, href] of d.files) files.appendChild(el('a', { href: href }, name));
    } else {
      files.textContent = 'no per-design files were written (--no-export)';
    }
    drawCreasePattern(d);
    if (view) view.show(d);
    setFrame(d.geometry.frames.length ? d.geometry.frames.length - 1 : 0);
  }

  // A design the page carries as a row only: its row's values, and the command that draws
  // it (its design JSON is beside the report).
  function selectRowOnly(r) {
    const text = (key) => {
      const k = colIndex.get(key);
      return k === undefined ? '–' : cellText(r.v[k], cols[k].format);
    };
    const parts = [r.id, text('sequence')];
    if (colIndex.has('candidate') && r.v[colIndex.get('candidate')] !== null) parts.push('candidate ' + text('candidate'));
    document.getElementById('detail-title').textContent = parts.join(' — ');
    const facts = document.getElementById('detail-facts').tBodies[0];
    facts.replaceChildren();
    cols.forEach((c, k) => {
      const tr = el('tr');
      tr.appendChild(el('th', {}, heads[k].textContent));
      tr.appendChild(el('td', {}, cellText(r.v[k], c.format)));
      facts.appendChild(tr);
    });
    billTable(null);
    const files = document.getElementById('detail-files');
    files.replaceChildren();
    files.appendChild(document.createTextNode('This page carries the ' + data.designs.length + ' most robust designs in full (--report-designs). To view this one: '));
    files.appendChild(el('code', {}, 'foldsynth export designs/' + r.id + '.json --format all --out designs/' + r.id));
    files.appendChild(document.createTextNode(' (beside this report), or open '));
    files.appendChild(el('a', { href: 'designs/' + encodeURIComponent(r.id) + '.json' }, 'its design JSON'));
    files.appendChild(document.createTextNode('.'));
  }

  // The bill of the build of a thick design: the setting, every crease as a hinge, every
  // panel; hidden for a design without [fabrication].
  function billTable(bill) {
    const table = document.getElementById('detail-bill');
    const body = table.tBodies[0];
    body.replaceChildren();
    table.hidden = !bill;
    if (!bill) return;
    const row = (cells, head) => {
      const tr = el('tr');
      cells.forEach((c, i) => tr.appendChild(el(head || i === 0 ? 'th' : 'td', {}, String(c))));
      body.appendChild(tr);
    };
    const mm = (x) => x.toFixed(2);
    row(['setting', bill.method + ', ' + bill.sides + ' side(s), ' + mm(bill.thickness_mm) + ' mm thick, ' + mm(bill.scale_mm_per_unit) + ' mm per unit, hinge gap ' + mm(bill.hinge_gap_mm) + ' mm']);
    row(['crease', 'vertices', 'panels', 'largest fold (°)', 'setback +/− (mm)', 'gap (mm)', 'hinge length (mm)'], true);
    for (const c of bill.creases) {
      row(['e' + c.edge, c.vertices.join('–'), c.facets.join(', '), c.largest_fold_deg.toFixed(1), mm(c.setback_mm[0]) + ' / ' + mm(c.setback_mm[1]), mm(c.gap_mm), mm(c.hinge_length_mm)]);
    }
    row(['panel', 'thickness (mm)', 'area (mm²)', 'corners'], true);
    for (const p of bill.panels) row(['f' + p.facet, mm(p.thickness_mm), p.area_mm2.toFixed(0), p.outline_mm.length]);
    row(['total area (mm²)', bill.total_area_mm2.toFixed(0)]);
  }

  function robustnessFacts(r) {
    const out = [];
    if (typeof r.score === 'number') out.push(['robustness score', fmt(r.score)]);
    const names = MARGIN_NAMES;
    for (const key in names) {
      const m = r[key];
      if (!m || typeof m.value !== 'number') continue;
      let text = fmt(m.value) + ' (setting ' + fmt(m.setting) + ')';
      if (typeof m.t === 'number') text += ' at t = ' + m.t.toFixed(4);
      if (m.where) text += ', ' + m.where;
      out.push([names[key], text]);
    }
    return out;
  }

  function fmt(x) {
    if (typeof x !== 'number') return '–';
    if (x === 0) return '0';
    const a = Math.abs(x);
    return a >= 1e-3 && a < 1e4 ? x.toPrecision(4) : x.toExponential(3);
  }

  // ---- crease pattern (SVG) ---------------------------------------------------------------
  const SVG = 'http://www.w3.org/2000/svg';
  const CP_COLORS = { B: '#000000', M: '#d62728', V: '#1f5fd6', F: '#9a9a9a' };

  function svgEl(tag, attrs, text) {
    const e = document.createElementNS(SVG, tag);
    for (const k in attrs) e.setAttribute(k, attrs[k]);
    if (text !== undefined) e.textContent = text;
    return e;
  }

  function drawCreasePattern(d) {
    const svg = document.getElementById('cp');
    svg.replaceChildren();
    const g = d.geometry;
    const xs = g.flat.map((p) => p[0]);
    const ys = g.flat.map((p) => -p[1]); // SVG's y points down
    const minX = Math.min(...xs), maxX = Math.max(...xs);
    const minY = Math.min(...ys), maxY = Math.max(...ys);
    const size = Math.max(maxX - minX, maxY - minY, 1e-9);
    const pad = 0.08 * size;
    svg.setAttribute('viewBox', [minX - pad, minY - pad, maxX - minX + 2 * pad, maxY - minY + 2 * pad].join(' '));
    const pt = (i) => [g.flat[i][0], -g.flat[i][1]];
    for (let k = 0; k < g.tris.length; k += 3) {
      const pts = [g.tris[k], g.tris[k + 1], g.tris[k + 2]].map((i) => pt(i).join(',')).join(' ');
      svg.appendChild(svgEl('polygon', { points: pts, fill: '#fbf1e1', stroke: '#fbf1e1', 'stroke-width': 0.002 * size }));
    }
    g.edges.forEach((e, i) => {
      const a = pt(e[0]), b = pt(e[1]);
      svg.appendChild(svgEl('line', {
        x1: a[0], y1: a[1], x2: b[0], y2: b[1],
        stroke: CP_COLORS[g.assign[i]] || '#000000',
        'stroke-width': (g.driven.includes(i) ? 0.018 : 0.008) * size,
        'stroke-linecap': 'round',
        'data-assignment': g.assign[i],
      }));
    });
    const fs = 0.045 * size;
    g.flat.forEach((p, i) => {
      svg.appendChild(svgEl('text', { x: p[0] + 0.3 * fs, y: -p[1] - 0.3 * fs, 'font-size': fs, fill: '#444444', 'font-family': 'sans-serif' }, 'v' + (i + 1)));
    });
    if (d.gripping) {
      const a = pt(d.gripping - 1);
      svg.appendChild(svgEl('circle', { cx: a[0], cy: a[1], r: 0.03 * size, fill: 'none', stroke: '#000000', 'stroke-width': 0.008 * size }));
    }
  }

  // ---- 3D view (three.js) ------------------------------------------------------------------
  const slider = document.getElementById('t-slider');
  const tOut = document.getElementById('t-value');
  const playBtn = document.getElementById('play');
  const view = makeView();
  state.webgl = view !== null;

  function hasWebGL() {
    try {
      const c = document.createElement('canvas');
      return !!(c.getContext('webgl2') || c.getContext('webgl'));
    } catch (e) {
      return false;
    }
  }

  function makeView() {
    const T = window.FoldsynthThree;
    const canvas = document.getElementById('canvas3d');
    if (!T || !hasWebGL()) {
      canvas.hidden = true;
      document.getElementById('no-webgl').hidden = false;
      return null;
    }
    const renderer = new T.WebGLRenderer({ canvas: canvas, antialias: true, preserveDrawingBuffer: true });
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    const scene = new T.Scene();
    scene.background = new T.Color(0xf4f4f2);
    const camera = new T.PerspectiveCamera(35, 4 / 3, 0.01, 1000);
    camera.up.set(0, 0, 1); // the task's z is up
    scene.add(new T.AmbientLight(0xffffff, 1.3));
    const light = new T.DirectionalLight(0xffffff, 2.2);
    light.position.set(0.5, 0.8, 1.0); // relative to the camera: lit from where one looks
    camera.add(light);
    scene.add(camera);
    const controls = new T.OrbitControls(camera, canvas);
    controls.addEventListener('change', render);
    let content = null;
    let current = null; // per-design buffers updated for every t

    function render() {
      renderer.render(scene, camera);
    }

    function resize() {
      const w = canvas.clientWidth, h = canvas.clientHeight;
      if (!w || !h) return;
      renderer.setSize(w, h, false);
      camera.aspect = w / h;
      camera.updateProjectionMatrix();
      render();
    }
    new ResizeObserver(resize).observe(canvas);

    function dispose(obj) {
      obj.traverse((o) => {
        if (o.geometry) o.geometry.dispose();
        if (o.material) o.material.dispose();
      });
    }

    function lineGeometry(points) {
      const g = new T.BufferGeometry();
      g.setAttribute('position', new T.BufferAttribute(new Float32Array(points.flat()), 3));
      return g;
    }

    // side 2 is three.js's DoubleSide (not among the bundle's exports).
    const translucent = (color, opacity) => new T.MeshLambertMaterial({ color: color, transparent: true, opacity: opacity, depthWrite: false, side: 2 });

    function meshGeometry(m) {
      const g = new T.BufferGeometry();
      g.setAttribute('position', new T.BufferAttribute(new Float32Array(m.vertices), 3));
      g.setIndex(m.triangles);
      g.computeVertexNormals();
      return g;
    }

    // A square of half side h about point p, normal to the unit n (two triangles).
    function square(p, nrm, h, material) {
      const n3 = new T.Vector3().fromArray(nrm);
      const helper = Math.abs(n3.x) < 0.9 ? new T.Vector3(1, 0, 0) : new T.Vector3(0, 1, 0);
      const u = helper.cross(n3).normalize();
      const v = n3.clone().cross(u);
      const c = new T.Vector3().fromArray(p);
      const corner = (a, b) => c.clone().add(u.clone().multiplyScalar(a * h)).add(v.clone().multiplyScalar(b * h)).toArray();
      const vertices = [corner(-1, -1), corner(1, -1), corner(1, 1), corner(-1, 1)].flat();
      return new T.Mesh(meshGeometry({ vertices: vertices, triangles: [0, 1, 2, 0, 2, 3] }), material);
    }

    // A box's 12 triangles from its 8 corners (corner k: + on axis i where bit i is set).
    const BOX_TRIANGLES = [0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5];

    // The point of the plane (p, n) nearest to c.
    function foot(p, nrm, c) {
      const n3 = new T.Vector3().fromArray(nrm);
      const d = c.clone().sub(new T.Vector3().fromArray(p)).dot(n3);
      return c.clone().sub(n3.multiplyScalar(d)).toArray();
    }

    // The 12 edges of a box given by its 8 corners (corner k: + on axis i where bit i is set).
    function boxEdges(corners, color) {
      const seg = [];
      for (let k = 0; k < 8; k += 1) {
        for (const bit of [1, 2, 4]) if (!(k & bit)) seg.push(corners[k], corners[k | bit]);
      }
      return new T.LineSegments(lineGeometry(seg), new T.LineBasicMaterial({ color: color }));
    }

    // Obstacles (grey, translucent), containment boxes (wireframes) and goals other than
    // points (green): a line as a long segment, a plane as a square, a surface as its mesh.
    // Each object is named kind:name so a test (or a person in the console) can find it.
    function drawScene(world, goals, center, radius) {
      const out = [];
      const grey = () => translucent(0x8a8a8a, 0.35);
      world.obstacles.forEach((o) => {
        let obj = null;
        if (o.shape === 'cylinder') {
          const a = new T.Vector3().fromArray(o.a);
          const b = new T.Vector3().fromArray(o.b);
          const axis = b.clone().sub(a);
          obj = new T.Mesh(new T.CylinderGeometry(o.radius, o.radius, axis.length(), 48, 1, false), grey());
          obj.position.copy(a.clone().add(b).multiplyScalar(0.5));
          obj.quaternion.setFromUnitVectors(new T.Vector3(0, 1, 0), axis.normalize());
        } else if (o.shape === 'sphere') {
          obj = new T.Mesh(new T.SphereGeometry(o.radius, 32, 16), grey());
          obj.position.fromArray(o.center);
        } else if (o.shape === 'box') {
          obj = new T.Mesh(meshGeometry({ vertices: o.corners.flat(), triangles: BOX_TRIANGLES }), grey());
        } else if (o.shape === 'halfspace') {
          obj = square(foot(o.point, o.normal, center), o.normal, 1.5 * radius, grey());
        } else if (o.shape === 'mesh' && o.mesh) {
          obj = new T.Mesh(meshGeometry(o.mesh), grey());
        }
        if (obj) {
          obj.name = 'obstacle:' + o.shape + ':' + o.name;
          out.push(obj);
        }
      });
      world.containment.forEach((c) => {
        const box = boxEdges(c.corners, 0x6a3d9a);
        box.name = 'containment:' + c.name;
        out.push(box);
      });
      const green = () => translucent(0x2e8b57, 0.3);
      goals.forEach((g, i) => {
        let obj = null;
        if (g.kind === 'line') {
          // The line's point nearest the view's centre, ± two view radii along it.
          const u0 = new T.Vector3().fromArray(g.direction);
          const p0 = new T.Vector3().fromArray(g.point);
          const p = p0.clone().add(u0.clone().multiplyScalar(center.clone().sub(p0).dot(u0)));
          const u = new T.Vector3().fromArray(g.direction).multiplyScalar(2 * radius);
          obj = new T.Line(lineGeometry([p.clone().sub(u).toArray(), p.clone().add(u).toArray()]), new T.LineBasicMaterial({ color: 0x2e8b57 }));
        } else if (g.kind === 'plane') {
          obj = square(foot(g.point, g.normal, center), g.normal, radius, green());
        } else if (g.kind === 'surface' && world.surfaces[g.index]) {
          obj = new T.Mesh(meshGeometry(world.surfaces[g.index]), green());
        }
        if (obj) {
          obj.name = 'goal:' + g.kind + ':' + i;
          out.push(obj);
        }
      });
      return out;
    }

    function show(d) {
      if (content) {
        scene.remove(content);
        dispose(content);
      }
      content = new T.Group();
      const g = d.geometry;
      const n = g.flat.length;
      const frames = g.frames.length ? g.frames : [g.flat.flatMap((p) => [p[0], p[1], 0])];
      // Facets: one vertex per triangle corner, so every facet gets its own flat normal.
      const faceGeo = new T.BufferGeometry();
      faceGeo.setAttribute('position', new T.BufferAttribute(new Float32Array(g.tris.length * 3), 3));
      const edgeGeo = new T.BufferGeometry();
      edgeGeo.setAttribute('position', new T.BufferAttribute(new Float32Array(g.edges.length * 6), 3));
      const colors = new Float32Array(g.edges.length * 6);
      const EDGE = { B: 0x222222, M: 0xd62728, V: 0x1f5fd6, F: 0x9a9a9a };
      g.edges.forEach((e, i) => {
        const c = new T.Color(EDGE[g.assign[i]] || 0x222222);
        colors.set([c.r, c.g, c.b, c.r, c.g, c.b], 6 * i);
      });
      edgeGeo.setAttribute('color', new T.BufferAttribute(colors, 3));
      const offset = { polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 };
      // Thick panels ([fabrication]): every panel's triangles, one vertex per corner, moved
      // by its facet's rigid motion in setFrame; they replace the zero-thickness facets.
      let thickGeo = null;
      if (d.thick && d.thick.panels.length) {
        const count = d.thick.panels.reduce((s, p) => s + p.triangles.length, 0);
        thickGeo = new T.BufferGeometry();
        thickGeo.setAttribute('position', new T.BufferAttribute(new Float32Array(count * 3), 3));
      }
      const arm = (front, back, lines) => {
        const group = new T.Group();
        const a = new T.Mesh(faceGeo, new T.MeshLambertMaterial(Object.assign({ color: front, side: T.FrontSide }, offset)));
        const b = new T.Mesh(faceGeo, new T.MeshLambertMaterial(Object.assign({ color: back, side: T.BackSide }, offset)));
        const l = new T.LineSegments(edgeGeo, new T.LineBasicMaterial({ vertexColors: true, transparent: lines < 1, opacity: lines }));
        const parts = [a, b, l];
        if (thickGeo) {
          a.visible = false;
          b.visible = false;
          parts.push(new T.Mesh(thickGeo, new T.MeshLambertMaterial({ color: front, side: T.FrontSide })));
        }
        for (const o of parts) {
          o.frustumCulled = false; // the bounds change with t
          group.add(o);
        }
        return group;
      };
      const first = arm(0xf0a860, 0x7fa7d9, 1);
      first.name = 'arm:1';
      content.add(first);
      const world = (data.scenes && data.scenes[d.scene]) || { obstacles: [], copies: { n: 1 }, containment: [], surfaces: [] };
      // Copy k: the arm turned by 2πk/n about the copies' axis (sharing the arm's geometry,
      // so the t slider moves every copy).
      // (The bundled three.js has no Matrix4: a copy is a quaternion and a position.)
      const copies = [];
      const cp = world.copies;
      for (let k = 1; k < (cp.n || 1); k += 1) {
        const axis = new T.Vector3().fromArray(cp.direction);
        const angle = (2 * Math.PI * k) / cp.n;
        const at = new T.Vector3().fromArray(cp.point);
        const shift = at.clone().sub(at.clone().applyAxisAngle(axis, angle));
        const copy = arm(0xf7d2ad, 0xbcd0ea, 0.45);
        copy.name = 'arm:' + (k + 1);
        copy.quaternion.setFromAxisAngle(axis, angle);
        copy.position.copy(shift);
        content.add(copy);
        copies.push({ axis: axis, angle: angle, shift: shift });
      }
      // Everything the view should frame: every frame of every copy, targets, obstacles.
      const pts = [];
      const v3 = new T.Vector3();
      for (const f of frames) {
        for (let i = 0; i < n; i += 1) {
          pts.push([f[3 * i], f[3 * i + 1], f[3 * i + 2]]);
          for (const c of copies) pts.push(v3.set(f[3 * i], f[3 * i + 1], f[3 * i + 2]).applyAxisAngle(c.axis, c.angle).add(c.shift).toArray());
        }
      }
      for (const p of d.targets.concat(d.trajectory)) pts.push(p);
      for (const o of world.obstacles) {
        if (o.shape === 'cylinder') pts.push(o.a, o.b);
        else if (o.shape === 'sphere') pts.push(o.center);
        else if (o.shape === 'box') pts.push(...o.corners);
      }
      const lo = [0, 1, 2].map((k) => Math.min(...pts.map((p) => p[k])));
      const hi = [0, 1, 2].map((k) => Math.max(...pts.map((p) => p[k])));
      const center = new T.Vector3((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2);
      const radius = Math.max(1e-6, 0.5 * Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]));
      const dot = (r, color) => new T.Mesh(new T.SphereGeometry(r, 20, 14), new T.MeshLambertMaterial({ color: color }));
      for (const p of d.targets) {
        const s = dot(0.03 * radius, 0x2e8b57);
        s.position.set(p[0], p[1], p[2]);
        content.add(s);
      }
      if (d.trajectory.length > 1) {
        content.add(new T.Line(lineGeometry(d.trajectory), new T.LineBasicMaterial({ color: 0x2e8b57 })));
      }
      let marker = null;
      const gv = d.gripping ? d.gripping - 1 : -1;
      if (gv >= 0 && gv < n) {
        const path = frames.map((f) => [f[3 * gv], f[3 * gv + 1], f[3 * gv + 2]]);
        if (path.length > 1) content.add(new T.Line(lineGeometry(path), new T.LineBasicMaterial({ color: 0x333333 })));
        marker = dot(0.022 * radius, 0x111111);
        content.add(marker);
      }
      for (const o of drawScene(world, d.goals || [], center, radius)) content.add(o);
      scene.add(content);
      current = { d: d, frames: frames, faceGeo: faceGeo, edgeGeo: edgeGeo, thickGeo: thickGeo, marker: marker, gv: gv, n: n };
      // Front, right, above: the folded arm and its target in view.
      const dir = new T.Vector3(0.55, -1.0, 0.6).normalize();
      const dist = (radius / Math.sin((camera.fov * Math.PI) / 360)) * 0.9;
      camera.position.copy(center.clone().add(dir.multiplyScalar(dist)));
      camera.near = dist / 100;
      camera.far = dist * 10;
      camera.updateProjectionMatrix();
      controls.target.copy(center);
      controls.update();
    }

    // Vertex positions at fractional frame x: linear between the two nearest frames (each
    // is an exact state of the rigid motion; the frames are dense enough to look smooth).
    function setFrame(x) {
      if (!current) return;
      const fr = current.frames;
      const i = Math.min(Math.floor(x), fr.length - 1);
      const j = Math.min(i + 1, fr.length - 1);
      const w = x - i;
      const a = fr[i], b = fr[j];
      const at = (v, k) => a[3 * v + k] * (1 - w) + b[3 * v + k] * w;
      const tris = current.d.geometry.tris;
      const fp = current.faceGeo.attributes.position;
      for (let k = 0; k < tris.length; k += 1) fp.setXYZ(k, at(tris[k], 0), at(tris[k], 1), at(tris[k], 2));
      fp.needsUpdate = true;
      current.faceGeo.computeVertexNormals();
      const ep = current.edgeGeo.attributes.position;
      current.d.geometry.edges.forEach((e, k) => {
        ep.setXYZ(2 * k, at(e[0], 0), at(e[0], 1), at(e[0], 2));
        ep.setXYZ(2 * k + 1, at(e[1], 0), at(e[1], 1), at(e[1], 2));
      });
      ep.needsUpdate = true;
      if (current.thickGeo) moveThick(current.d, current.thickGeo, at);
      if (current.marker) current.marker.position.set(at(current.gv, 0), at(current.gv, 1), at(current.gv, 2));
      render();
    }

    // Each thick panel moved by its facet's rigid motion: the orthonormal frame of three of
    // the facet's corners in the flat layout taken to theirs at the frame (`at`).
    function moveThick(d, geo, at) {
      const flat = d.geometry.flat;
      const frameOf = (p) => {
        const e1 = p[1].clone().sub(p[0]).normalize();
        const n = e1.clone().cross(p[2].clone().sub(p[0])).normalize();
        return [p[0], e1, n.clone().cross(e1), n];
      };
      const pos = geo.attributes.position;
      let k = 0;
      for (const panel of d.thick.panels) {
        const c = panel.corners;
        const [p0, a1, a2, an] = frameOf(c.map((v) => new T.Vector3(flat[v][0], flat[v][1], 0)));
        const [q0, b1, b2, bn] = frameOf(c.map((v) => new T.Vector3(at(v, 0), at(v, 1), at(v, 2))));
        const vs = panel.vertices;
        for (const i of panel.triangles) {
          const x = new T.Vector3(vs[3 * i], vs[3 * i + 1], vs[3 * i + 2]).sub(p0);
          const y = q0.clone()
            .add(b1.clone().multiplyScalar(x.dot(a1)))
            .add(b2.clone().multiplyScalar(x.dot(a2)))
            .add(bn.clone().multiplyScalar(x.dot(an)));
          pos.setXYZ(k, y.x, y.y, y.z);
          k += 1;
        }
      }
      pos.needsUpdate = true;
      geo.computeVertexNormals();
    }

    // Names of the objects in the view (arms, obstacles, boxes, goals), in drawing order.
    function names() {
      return content ? content.children.map((o) => o.name).filter((x) => x) : [];
    }

    return { show: show, setFrame: setFrame, names: names };
  }

  function setFrame(x) {
    const d = byId.get(state.selected);
    if (!d) return;
    const n = Math.max(d.geometry.frames.length, 1);
    x = Math.min(Math.max(x, 0), n - 1);
    state.frame = x;
    slider.max = String(n - 1);
    slider.value = String(x);
    const ts = d.geometry.t;
    let text = 'flat state';
    if (ts.length) {
      const i = Math.min(Math.floor(x), ts.length - 1);
      const j = Math.min(i + 1, ts.length - 1);
      const t = ts[i] + (ts[j] - ts[i]) * (x - i);
      text = 't = ' + t.toFixed(4) + ' (' + ((t * 180) / Math.PI).toFixed(1) + '°)';
    }
    tOut.value = text;
    tOut.textContent = text;
    if (view) view.setFrame(x);
  }

  slider.addEventListener('input', () => setFrame(Number(slider.value)));

  // Play: the whole motion in about 3 s, then again from the flat state.
  let last = null;
  function tick(now) {
    if (!state.playing) return;
    const d = byId.get(state.selected);
    const n = d ? d.geometry.frames.length : 0;
    if (n > 1 && last !== null) {
      let x = state.frame + ((now - last) / 3000) * (n - 1);
      if (x > n - 1) x = 0;
      setFrame(x);
    }
    last = now;
    requestAnimationFrame(tick);
  }
  playBtn.addEventListener('click', () => {
    state.playing = !state.playing;
    playBtn.textContent = state.playing ? 'pause' : 'play';
    last = null;
    if (state.playing) requestAnimationFrame(tick);
  });

  // Most robust first when the records carry robustness; otherwise the search's order.
  if (heads.some((h) => h.dataset.key === 'score')) state.sort = { key: 'score', dir: -1 };
  if (state.sort) sortBy(state.sort.key, state.sort.dir);
  applyFilters();
  // The first design carried in full (the most robust), else the first row.
  const first = state.view.find((r) => byId.has(r.id)) || state.view[0];
  if (first) select(first.id);
})();

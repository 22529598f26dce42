// Drives Debian's Chromium (headless, over the DevTools protocol, with puppeteer-core) through
// report.html pages the way a person would (keys on the slider, clicks on column headers,
// rows, the play button, a mouse drag on the 3D view) and prints what it saw as one JSON
// document on stdout. tests/export_report.rs runs it and asserts on the observations.
//
// node report_check.mjs --chromium /usr/bin/chromium --broken BROKEN.html REPORT.html...

import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import puppeteer from 'puppeteer-core';

const args = process.argv.slice(2);
let chromium = '/usr/bin/chromium';
let broken = null;
const reports = [];
for (let i = 0; i < args.length; i += 1) {
  if (args[i] === '--chromium') chromium = args[++i];
  else if (args[i] === '--broken') broken = args[++i];
  else reports.push(args[i]);
}

const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'foldsynth-chromium-'));
const browser = await puppeteer.launch({
  executablePath: chromium,
  headless: true,
  userDataDir: profile,
  args: [
    '--no-sandbox',
    '--disable-gpu',
    '--disable-quic',
    '--no-first-run',
    '--disable-background-networking',
    '--disable-component-update',
    '--disable-sync',
    // WebGL in software (SwiftShader); the page is our own, trusted content.
    '--enable-unsafe-swiftshader',
  ],
});

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

async function open(file) {
  const page = await browser.newPage();
  await page.setViewport({ width: 1500, height: 1100 });
  const log = { errors: [], warnings: [] };
  page.on('console', (m) => {
    const t = m.type();
    const text = `console.${t}: ${m.text()}`;
    if (t === 'error' || t === 'assert') log.errors.push(text);
    else if (t === 'warn' || t === 'warning') log.warnings.push(text);
  });
  page.on('pageerror', (e) => log.errors.push(`exception: ${e.message}`));
  page.on('requestfailed', (r) => log.errors.push(`request failed: ${r.url()} ${r.failure()?.errorText}`));
  const requests = [];
  page.on('request', (r) => requests.push(r.url()));
  await page.goto('file://' + path.resolve(file), { waitUntil: 'load' });
  return { page, log, requests };
}

// The 3D canvas as pixels: how many differ from the background, and a coarse grey
// thumbnail (64 × 48) to compare two moments.
async function pixels(page) {
  return page.evaluate(() => {
    const c = document.getElementById('canvas3d');
    if (!c || c.hidden || !c.width) return null;
    const d = document.createElement('canvas');
    d.width = c.width;
    d.height = c.height;
    const x = d.getContext('2d');
    x.drawImage(c, 0, 0);
    const im = x.getImageData(0, 0, d.width, d.height).data;
    const bg = [244, 244, 242];
    let ink = 0;
    for (let i = 0; i < im.length; i += 4) {
      if (Math.abs(im[i] - bg[0]) + Math.abs(im[i + 1] - bg[1]) + Math.abs(im[i + 2] - bg[2]) > 24) ink += 1;
    }
    const W = 64, H = 48;
    const s = document.createElement('canvas');
    s.width = W;
    s.height = H;
    const sx = s.getContext('2d');
    sx.drawImage(c, 0, 0, W, H);
    const sm = sx.getImageData(0, 0, W, H).data;
    const thumb = [];
    for (let i = 0; i < sm.length; i += 4) thumb.push(Math.round((sm[i] + sm[i + 1] + sm[i + 2]) / 3));
    return { width: d.width, height: d.height, ink, total: d.width * d.height, thumb };
  });
}

function changed(a, b) {
  if (!a || !b) return null;
  let n = 0;
  for (let i = 0; i < a.thumb.length; i += 1) if (Math.abs(a.thumb[i] - b.thumb[i]) > 8) n += 1;
  return n;
}

const strip = (p) => p && { width: p.width, height: p.height, ink: p.ink, total: p.total };

async function tableState(page) {
  return page.evaluate(() => {
    const rows = Array.from(document.querySelectorAll('#design-table tbody tr'));
    return {
      order: rows.map((r) => r.dataset.id),
      visible: rows.filter((r) => !r.hidden).map((r) => r.dataset.id),
      shown: document.getElementById('shown').textContent,
      headers: Array.from(document.querySelectorAll('#design-table thead th')).map((h) => [h.dataset.key, h.getAttribute('aria-sort')]),
      selected: window.foldsynthReport.selected,
      title: document.getElementById('detail-title').textContent,
    };
  });
}

async function detail(page) {
  return page.evaluate(() => ({
    selected: window.foldsynthReport.selected,
    frame: window.foldsynthReport.frame,
    webgl: window.foldsynthReport.webgl,
    objects: window.foldsynthReport.objects,
    t: document.getElementById('t-value').textContent,
    slider: { min: document.getElementById('t-slider').min, max: document.getElementById('t-slider').max, value: document.getElementById('t-slider').value },
    title: document.getElementById('detail-title').textContent,
    facts: Array.from(document.querySelectorAll('#detail-facts tr')).map((r) => [r.cells[0].textContent, r.cells[1].textContent]),
    files: Array.from(document.querySelectorAll('#detail-files a')).map((a) => [a.textContent, a.getAttribute('href')]),
    cp: {
      lines: Array.from(document.querySelectorAll('#cp line')).map((l) => l.getAttribute('data-assignment')),
      labels: Array.from(document.querySelectorAll('#cp text')).map((t) => t.textContent),
      circles: document.querySelectorAll('#cp circle').length,
    },
  }));
}

async function check(file) {
  const started = Date.now();
  const { page, log, requests } = await open(file);
  const out = { file };
  await page.waitForFunction(() => window.foldsynthReport && window.foldsynthReport.selected !== null, { timeout: 20000 });
  // From opening the tab to the first design drawn and selected (issue 34: a large run's
  // page opens in seconds). Reported, never asserted: the machines are shared.
  out.open_ms = Date.now() - started;
  await sleep(200);
  out.initial = { table: await tableState(page), detail: await detail(page) };
  const first = await pixels(page);
  out.pixels_initial = strip(first);

  // The slider, by keyboard as a person would: Home = the flat state, End = the last frame.
  await page.focus('#t-slider');
  await page.keyboard.press('Home');
  await sleep(100);
  const flat = await pixels(page);
  out.slider_home = { detail: await detail(page), pixels: strip(flat), changed_vs_initial: changed(first, flat) };
  await page.keyboard.press('End');
  await sleep(100);
  const end = await pixels(page);
  out.slider_end = { detail: await detail(page), pixels: strip(end), changed_vs_home: changed(flat, end) };

  // Mouse drag on the 3D view rotates it.
  const box = await (await page.$('#canvas3d')).boundingBox();
  await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
  await page.mouse.down();
  await page.mouse.move(box.x + box.width / 2 + 120, box.y + box.height / 2 + 30, { steps: 8 });
  await page.mouse.up();
  await sleep(150);
  const rotated = await pixels(page);
  out.drag = { changed_vs_end: changed(end, rotated), pixels: strip(rotated) };

  // Play for a moment, then pause.
  await page.click('#play');
  const before = (await detail(page)).frame;
  await sleep(700);
  await page.click('#play');
  const after = await detail(page);
  out.play = { frame_before: before, frame_after: after.frame, button: await page.$eval('#play', (b) => b.textContent) };

  // Sorting: click a header twice (ascending, then descending) for each sortable key.
  out.sorts = {};
  const keys = (await tableState(page)).headers.map((h) => h[0]);
  for (const key of keys) {
    await page.click(`#design-table thead th[data-key="${key}"]`);
    const asc = (await tableState(page)).order;
    await page.click(`#design-table thead th[data-key="${key}"]`);
    const desc = await tableState(page);
    out.sorts[key] = { asc, desc: desc.order, aria: desc.headers.find((h) => h[0] === key)[1] };
  }

  // Filtering: each choice filter set to its last option, then back to all.
  out.filters = {};
  const choices = await page.$$eval('#design-table select[data-filter=choice]', (ss) => ss.map((s) => [s.dataset.key, Array.from(s.options).map((o) => o.value)]));
  for (const [key, options] of choices) {
    const value = options[options.length - 1];
    await page.select(`#design-table select[data-key="${key}"]`, value);
    out.filters[key] = { value, ...(await tableState(page)) };
    await page.select(`#design-table select[data-key="${key}"]`, '');
  }
  // A numeric filter typed in: Ω* at most the median objective of the rows.
  const objectives = await page.$$eval('#design-table tbody td[data-key=objective]', (tds) => tds.map((t) => Number(t.dataset.v)).sort((a, b) => a - b));
  if (objectives.length) {
    const limit = objectives[Math.floor((objectives.length - 1) / 2)];
    await page.type('#design-table input[data-key=objective]', String(limit));
    out.filters.objective = { value: limit, ...(await tableState(page)) };
    await page.$eval('#design-table input[data-key=objective]', (i) => { i.value = ''; i.dispatchEvent(new Event('input')); });
  }
  const minScore = await page.$('#design-table input[data-key=score]');
  if (minScore) {
    await page.type('#design-table input[data-key=score]', '1.5');
    out.filters.score = { value: 1.5, ...(await tableState(page)) };
    await page.$eval('#design-table input[data-key=score]', (i) => { i.value = ''; i.dispatchEvent(new Event('input')); });
  }

  // Selecting another design by clicking its row.
  const ids = (await tableState(page)).order;
  const other = ids[ids.length - 1];
  const beforeSelect = await pixels(page);
  await page.click(`#design-table tbody tr[data-id="${other}"]`);
  await sleep(150);
  out.select = { clicked: other, detail: await detail(page), changed: changed(beforeSelect, await pixels(page)) };

  out.errors = log.errors;
  // Paging: the page of rows shown, the next page, and a design carried as a row only.
  const pager = async () => page.evaluate(() => ({
    info: document.getElementById('page-info').textContent,
    page: window.foldsynthReport.page,
    pages: window.foldsynthReport.pages,
    rows: Array.from(document.querySelectorAll('#design-table tbody tr')).map((r) => r.dataset.id),
    nextDisabled: document.getElementById('page-next').disabled,
  }));
  out.pager = { first: await pager() };
  if (!out.pager.first.nextDisabled) {
    await page.click('#page-next');
    out.pager.next = await pager();
  }
  const rowOnly = await page.evaluate(() => {
    const data = JSON.parse(document.getElementById('foldsynth-data').textContent);
    const full = new Set(data.designs.map((d) => d.id));
    const shown = Array.from(document.querySelectorAll('#design-table tbody tr')).map((r) => r.dataset.id);
    return shown.find((id) => !full.has(id)) || null;
  });
  if (rowOnly) {
    await page.click(`#design-table tbody tr[data-id="${rowOnly}"]`);
    out.rowOnly = await page.evaluate(() => ({
      selected: window.foldsynthReport.selected,
      title: document.getElementById('detail-title').textContent,
      files: document.getElementById('detail-files').textContent,
      viewsHidden: document.querySelector('#detail .views').hidden,
      facts: document.querySelectorAll('#detail-facts tr').length,
    }));
  }

  out.warnings = log.warnings;
  out.requests = requests.filter((u) => !u.startsWith('file://' + path.resolve(file)) && !u.startsWith('data:'));
  await page.close();
  return out;
}

const result = { reports: [] };
try {
  if (broken) {
    const { page, log } = await open(broken);
    await sleep(300);
    result.broken = { errors: log.errors };
    await page.close();
  }
  for (const f of reports) result.reports.push(await check(f));
} catch (e) {
  result.failure = String(e && e.stack ? e.stack : e);
} finally {
  await browser.close();
  fs.rmSync(profile, { recursive: true, force: true });
}
process.stdout.write(JSON.stringify(result) + '\n');

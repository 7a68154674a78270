// Checks an HTML report of `handlabel compare` in headless Debian Chromium:
//  - every table cell that names a JSON number (data-json="methods.0.metrics.mpjpe_mm",
//    data-decimals="2") shows that number of the JSON summary, rounded as it says
//    ("-" for null); the results table has one such cell per method and column;
//  - every image has loaded (naturalWidth > 0);
//  - the console shows no errors and the page makes no network request (only data:
//    and file: URLs);
// and saves a full-page screenshot. With --self-test it also checks two deliberately
// broken copies (an image reference broken, one number changed) and fails unless the
// check rejects both.
// Usage: node check-report.mjs REPORT.html SUMMARY.json [--screenshot PNG] [--self-test]
// Exit status: 0 passed, 1 failed, 2 bad usage.
import { chromium } from 'playwright-core';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

const CHROMIUM = process.env.CHROMIUM || '/usr/bin/chromium';
const LAUNCH_ARGS = ['--headless', '--no-sandbox', '--disable-gpu',
  '--disable-background-networking', '--no-first-run'];

function jsonAt(doc, dotted) {
  let v = doc;
  for (const key of dotted.split('.')) {
    if (v === null || v === undefined) return undefined;
    v = v[key];
  }
  return v;
}

// Problems found in one page (an empty list: it passed).
async function checkPage(browser, htmlPath, summary, screenshot) {
  const problems = [];
  const page = await browser.newPage({ viewport: { width: 1400, height: 900 } });
  page.on('console', (m) => {
    if (m.type() === 'error') problems.push(`console error: ${m.text()}`);
  });
  page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  await page.route('**/*', (route) => {
    const url = route.request().url();
    if (url.startsWith('data:') || url.startsWith('file:')) return route.continue();
    problems.push(`network request: ${url}`);
    return route.abort();
  });
  await page.goto(pathToFileURL(path.resolve(htmlPath)).href, { waitUntil: 'load' });
  const cells = await page.$$eval('td[data-json]', (tds) => tds.map((td) => ({
    path: td.dataset.json, decimals: Number(td.dataset.decimals), text: td.textContent.trim(),
    table: td.closest('table') ? td.closest('table').id : ''
  })));
  for (const c of cells) {
    const want = jsonAt(summary, c.path);
    if (want === undefined) {
      problems.push(`cell ${c.path}: not in the JSON`);
    } else if (want === null) {
      if (c.text !== '-') problems.push(`cell ${c.path}: shows ${c.text}, JSON has null`);
    } else {
      const got = Number(c.text);
      const tolerance = 0.5 * 10 ** -c.decimals + 1e-9 * Math.max(1, Math.abs(want));
      if (!Number.isFinite(got) || Math.abs(got - want) > tolerance) {
        problems.push(`cell ${c.path}: shows ${c.text}, JSON has ${want}`);
      }
    }
  }
  const resultCells = cells.filter((c) => c.table === 'results').length;
  const expected = (summary.methods || []).length * (summary.columns || []).length;
  if (expected === 0 || resultCells !== expected) {
    problems.push(`results table: ${resultCells} checked cells, expected ${expected}`);
  }
  const images = await page.$$eval('img', (imgs) => imgs.map((i) => ({
    alt: i.alt, complete: i.complete, width: i.naturalWidth })));
  if (images.length === 0) problems.push('no images');
  for (const i of images) {
    if (!i.complete || i.width <= 0) problems.push(`image not loaded: ${i.alt}`);
  }
  if (screenshot) await page.screenshot({ path: screenshot, fullPage: true });
  await page.close();
  return { problems, cells: cells.length, images: images.length };
}

// The two broken copies the check must reject.
function brokenCopies(html, dir) {
  const copies = [];
  const imgAt = html.indexOf('<img src="');
  if (imgAt >= 0) {
    const start = imgAt + '<img src="'.length;
    const end = html.indexOf('"', start);
    const broken = html.slice(0, start) + 'missing-picture.png' + html.slice(end);
    copies.push(['broken image reference', broken]);
  }
  const cell = /(<td data-json="[^"]*" data-decimals="(\d+)">)(-?[0-9.]+)(<\/td>)/;
  const m = html.match(cell);
  if (m) {
    const changed = (Number(m[3]) + 1).toFixed(Number(m[2]));
    copies.push(['changed number', html.replace(cell, `$1${changed}$4`)]);
  }
  return copies.map(([name, text], k) => {
    const file = path.join(dir, `broken-${k}.html`);
    fs.writeFileSync(file, text);
    return [name, file];
  });
}

async function main() {
  const args = process.argv.slice(2);
  const positional = args.filter((a, i) => !a.startsWith('--') &&
                                           args[i - 1] !== '--screenshot');
  if (positional.length !== 2) {
    console.error('usage: node check-report.mjs REPORT.html SUMMARY.json ' +
                  '[--screenshot PNG] [--self-test]');
    process.exit(2);
  }
  const [htmlPath, jsonPath] = positional;
  const shotAt = args.indexOf('--screenshot');
  const screenshot = shotAt >= 0 ? args[shotAt + 1] : '';
  const summary = JSON.parse(fs.readFileSync(jsonPath, 'utf8'));
  const browser = await chromium.launch({ executablePath: CHROMIUM, args: LAUNCH_ARGS });
  let failed = false;
  try {
    const r = await checkPage(browser, htmlPath, summary, screenshot);
    for (const p of r.problems) console.error(`check-report: ${htmlPath}: ${p}`);
    console.log(`check-report: ${htmlPath}: ${r.cells} numbers, ${r.images} images, ` +
                `${r.problems.length} problems`);
    failed = r.problems.length > 0;
    if (args.includes('--self-test')) {
      const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'check-report-'));
      const copies = brokenCopies(fs.readFileSync(htmlPath, 'utf8'), dir);
      if (copies.length !== 2) {
        console.error('check-report: self-test: could not make both broken copies');
        failed = true;
      }
      for (const [name, file] of copies) {
        const b = await checkPage(browser, file, summary, '');
        if (b.problems.length === 0) {
          console.error(`check-report: self-test: the copy with a ${name} PASSED`);
          failed = true;
        } else {
          console.log(`check-report: self-test: ${name} rejected: ${b.problems[0]}`);
        }
      }
      fs.rmSync(dir, { recursive: true, force: true });
    }
  } finally {
    await browser.close();
  }
  process.exit(failed ? 1 : 0);
}

main().catch((e) => {
  console.error(`check-report: ${e.stack || e}`);
  process.exit(1);
});

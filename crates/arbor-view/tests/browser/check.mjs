// The browser test of `arbor view`, run by crates/arbor-cli/tests/view_browser.rs:
//   node check.mjs CONFIG.json
// CONFIG: {"url": the URL `arbor view` printed, "chromium": the browser, "pixel": [x, y] to inspect,
// "results": where to write what the page showed, "screenshot": a PNG to save, or null, and
// "screenshot_pixel": [x, y] to inspect for it}.
//
// Drives the page in headless Chromium (playwright-core, with Debian's Chromium: no browser download)
// as a user would: waits for the first full frame, orbits by a drag, resets, rebuilds the structure as an
// octree, clicks a pixel, and asks without the token. It checks what only the browser can tell (the
// drag moved the image, the reset brought it back, requests without the token fail, no script error)
// and writes what the page shows (its canvas's pixels, the bytes it received, the stats panel, the
// inspector) for the Rust side to check against `arbor render` and `arbor info`. Any failure exits 1
// with its reason on stderr.
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { chromium } from "playwright-core";

const config = JSON.parse(readFileSync(process.argv[2], "utf8"));
/** How long any one wait may take: a hang guard, far beyond what the page needs. */
const WAIT = 60_000;
// The whole run may not hang either.
setTimeout(() => fail("the browser test did not finish within 5 minutes"), 300_000).unref();

function fail(message) {
  process.stderr.write(`browser test: ${message}\n`);
  process.exit(1);
}
function check(condition, message) {
  if (!condition) fail(message);
}

const profile = mkdtempSync(join(tmpdir(), "arbor-view-chromium-"));
const context = await chromium.launchPersistentContext(profile, {
  executablePath: config.chromium,
  headless: true,
  args: ["--no-sandbox", "--disable-gpu", "--disable-background-networking", "--disable-quic", "--no-first-run",
    "--disable-component-update", "--disable-sync"],
  viewport: { width: 1180, height: 860 },
  deviceScaleFactor: 1,
});
try {
  await run(context.pages()[0] || (await context.newPage()));
} catch (e) {
  fail(e.stack || String(e));
} finally {
  await context.close();
  rmSync(profile, { recursive: true, force: true });
}

async function run(page) {
  const errors = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  // The bytes of every image the page received, by view and samples.
  const received = new Map();
  page.on("response", async (r) => {
    if (!r.url().includes("/api/image") || r.status() !== 200) return;
    const h = r.headers();
    received.set(`${h["x-view"]}/${h["x-samples"]}`, (await r.body()).toString("base64"));
  });
  await page.goto(config.url);
  await page.waitForSelector("#stats tbody tr", { timeout: WAIT });

  // One sample: the page's first full frame is then `arbor render --spp 1` of the scene's camera.
  // Typed, then committed by leaving the field (as a user does): its one change event.
  await page.locator("#spp").fill("1");
  await page.locator("#spp").blur();
  const first = await settled(page, 0);
  const firstPixels = await canvasRgb(page);
  const firstReceived = received.get(`${first.view}/1`);
  check(firstReceived !== undefined, `the page drew view ${first.view} without receiving it`);

  // Orbit: a drag across the image.
  const box = await page.locator("#view").boundingBox();
  const [cx, cy] = [box.x + box.width / 2, box.y + box.height / 2];
  await page.mouse.move(cx, cy);
  await page.mouse.down();
  for (let i = 1; i <= 8; i++) await page.mouse.move(cx + 10 * i, cy + 3 * i);
  await page.mouse.up();
  const orbited = await settled(page, first.view);
  const orbitPixels = await canvasRgb(page);
  const changed = differing(firstPixels, orbitPixels);
  check(changed > orbitPixels.length / 3 / 10, `the drag changed only ${changed} pixels`);

  // Reset: back to the scene's camera, and to the same picture.
  await page.locator("#reset").click();
  const reset = await settled(page, orbited.view);
  check(differing(firstPixels, await canvasRgb(page)) === 0, "the reset view is not the first one");

  // Another structure: the stats panel shows it once it is built.
  await page.locator("#kind").selectOption("octree");
  await page.locator("#rebuild").click();
  await page.waitForSelector('#stats[data-kind="octree"]', { timeout: WAIT });
  const stats = await page.$$eval("#stats tbody tr", (rows) =>
    Object.fromEntries(rows.map((r) => [r.cells[0].textContent, r.cells[1].textContent])));
  check(/^built octree in /.test(await page.locator("#build-status").textContent()), "no build status");

  // Inspect a pixel by clicking it.
  const [x, y] = config.pixel;
  await page.mouse.click(box.x + x + 0.5, box.y + y + 0.5);
  await page.waitForSelector(`#inspect-panel[data-pixel="${x},${y}"]`, { timeout: WAIT });
  const inspected = await page.$eval("#inspect-panel", (p) => ({ ...p.dataset }));
  const rows = await page.locator("#inspector tbody tr").count();
  const segments = await page.locator("#rays line").count();
  const summary = await page.locator("#inspect-summary").textContent();
  check(rows >= 1 && segments >= 1, `the inspector shows ${rows} rays and draws ${segments}`);

  // Without the token, nothing: from the page's own origin, and from outside it.
  const refused = await page.evaluate(async () => {
    const statuses = [];
    for (const path of ["/api/scene", "/api/scene?token=0123", "/api/image?wait=0", "/"]) {
      statuses.push((await fetch(path)).status);
    }
    statuses.push((await fetch("/api/view", { method: "POST", body: "{}" })).status);
    return statuses;
  });
  const origin = new URL(config.url).origin;
  refused.push((await fetch(`${origin}/api/scene`)).status);
  check(refused.every((s) => s === 403), `requests without the token got ${refused}`);

  if (config.screenshot) await screenshot(page);
  check(errors.length === 0, `script errors on the page: ${errors.join("; ")}`);

  writeFileSync(config.results, JSON.stringify({
    first: { view: first.view, width: first.width, height: first.height, canvas: Buffer.from(firstPixels).toString("base64"),
      received: firstReceived },
    orbit: { view: orbited.view, changed }, reset: { view: reset.view },
    stats, inspected: { ...inspected, rows, segments, summary }, refused,
  }));
}

/** Waits until the page shows the one-sample frame of the view it last asked for, newer than `after`. */
async function settled(page, after) {
  await page.waitForFunction((after) => {
    const d = document.getElementById("view").dataset;
    return d.asked !== undefined && Number(d.asked) > after && d.view === d.asked && d.samples === "1";
  }, after, { timeout: WAIT });
  return page.evaluate(() => {
    const c = document.getElementById("render");
    return { view: Number(document.getElementById("view").dataset.view), width: c.width, height: c.height };
  });
}

/** The render canvas's pixels as RGB bytes (its alpha is opaque). */
async function canvasRgb(page) {
  const b64 = await page.evaluate(() => {
    const c = document.getElementById("render");
    const rgba = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
    let s = "";
    for (let i = 0; i < rgba.length; i += 4) {
      s += String.fromCharCode(rgba[i], rgba[i + 1], rgba[i + 2]);
    }
    return btoa(s);
  });
  return new Uint8Array(Buffer.from(b64, "base64"));
}

/** Pixels that differ between two RGB images of one size. */
function differing(a, b) {
  let n = 0;
  for (let i = 0; i < a.length; i += 3) {
    if (a[i] !== b[i] || a[i + 1] !== b[i + 1] || a[i + 2] !== b[i + 2]) n++;
  }
  return n;
}

/** docs/view.png: every panel in use (a box overlay, the inspected ray, both heatmaps, the chart). */
async function screenshot(page) {
  await page.locator("#overlay-kind").selectOption("boxes");
  await page.locator("#depth").fill("4");
  await page.locator("#depth").dispatchEvent("input");
  await page.locator("#overlay-kind").dispatchEvent("change");
  await page.waitForFunction(() => Number(document.getElementById("view").dataset.overlaySeq || 0) > 0, null, { timeout: WAIT });
  await page.locator("#compare").click();
  await page.waitForSelector("#compare-scale[data-scale]", { timeout: WAIT });
  await page.locator("#bench").click();
  await page.waitForFunction(() => /^done/.test(document.getElementById("bench-status").textContent), null, { timeout: WAIT });
  const [x, y] = config.screenshot_pixel;
  const box = await page.locator("#view").boundingBox();
  await page.mouse.click(box.x + x + 0.5, box.y + y + 0.5);
  await page.waitForSelector(`#inspect-panel[data-pixel="${x},${y}"]`, { timeout: WAIT });
  await page.screenshot({ path: config.screenshot, fullPage: true });
}

// Opens a polhode MCAP log in Foxglove Studio (studio-base 1.48, headless Chromium) with the
// shipped layout docs/viewers/polhode.foxglove-layout.json at two times, saves a screenshot of
// each and checks them: neither is blank, the body's 3D panel changed between the two (the
// body turned), and every plotted series is drawn. With --orbit (a log of a scenario with an
// orbit), the orbit panel is checked instead of the series: the Earth, the orbit path and the
// spacecraft marker are drawn and the panel changed between the two times (the spacecraft
// moved, the Earth turned); the plots need only not be blank (a rigid body's energies are 0
// and hide each other). With --effectors N, the body's 3D panel must also show at least N
// pixels of the effectors' red (a rotor or wheel disc, seen through the translucent body) at
// both times. Exits 1 with a message when a check fails.
//
// With --live URL instead of --log: Foxglove connects to a live run (`polhode run --live`,
// ds=foxglove-websocket) and takes one screenshot, NAME-live.png (NAME defaults to
// foxglove), as soon as the body and every plotted series are drawn (a live page never
// settles: new samples keep coming), or at --timeout; it is checked as one of the two above
// (the 3D panel not blank, the body drawn, every plotted series drawn).
//
//   node screenshots.mjs --log FILE.mcap [--out DIR] [--early S] [--late S] [--orbit]
//                        [--name NAME] [--effectors N] [--chromium PATH] [--timeout S]
//   node screenshots.mjs --live ws://127.0.0.1:PORT [--out DIR] [--name NAME] [--timeout S]
//
// --early and --late are seconds after the log's first message (default 10 and 120).
// Screenshots: DIR/NAME-early.png and DIR/NAME-late.png (NAME defaults to foxglove, or
// foxglove-orbit with --orbit; DIR to docs/figures/viewing in the repository).

import { open, readFile, mkdir, writeFile } from "node:fs/promises";
import { basename, dirname, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";
import { parseArgs } from "node:util";
import { createServer } from "http-server";
import { chromium } from "playwright-core";

const HERE = dirname(fileURLToPath(import.meta.url));
const REPO = resolve(HERE, "../../..");
const LAYOUT_FILE = join(REPO, "docs/viewers/polhode.foxglove-layout.json");
const LAYOUT_ID = "polhode"; // the id main.js gives the shipped layout

// Check thresholds (a 1600 x 900 viewport).
const MIN_DISTINCT_COLOURS = 16; // distinct colours (4 bits a channel) in a region
const MIN_FOREGROUND_FRACTION = 0.02; // pixels away from the region's commonest colour
const MIN_3D_CHANGE_FRACTION = 0.005; // 3D pixels that differ between the two times
const MIN_SERIES_PIXELS = 250; // pixels of a series' colour in its plot (a legend swatch has < 100)
const COLOUR_TOLERANCE = 40; // largest channel difference that still counts as a series colour
const PIXEL_DIFFERENCE = 30; // summed |dR|+|dG|+|dB| that makes two pixels differ
const MIN_BODY_PIXELS = 1000; // light grey pixels (the body) in the 3D panel; none without /scene
const MIN_BODY_PIXELS_ORBIT = 500; // with --orbit: the gravity-gradient smallsat is a slim box
// Live: the slender Explorer 1 hull seen at whatever attitude the run has reached when the
// plots are drawn (1004 to 1901 pixels measured); the log's check keeps the larger bound.
const MIN_BODY_PIXELS_LIVE = 500;
// The orbit panel (--orbit): blue-dominant pixels of the Earth's sphere, pixels of the orbit
// path's cyan and of the marker's magenta (none without /earth or /orbit_scene).
const MIN_EARTH_PIXELS = 5000;
const PATH_COLOUR = [77, 242, 242]; // rgb of (0.3, 0.95, 0.95) in src/log/orbit_scene.rs
const MIN_PATH_PIXELS = 150;
const MIN_MARKER_PIXELS = 20;
// --effectors: pixels of the effectors' red, rgb(217, 51, 64) in src/log/mod.rs, alone or
// through the body's translucent grey: red over green, a little blue over green (not the
// orange of the omega arrow, which has less blue than green).

const CHROMIUM_FLAGS = [
  "--no-sandbox",
  "--disable-background-networking",
  "--disable-component-update",
  "--disable-sync",
  "--no-first-run",
  "--disable-quic",
  "--use-angle=swiftshader",
  "--enable-unsafe-swiftshader",
];

// http-server uses a deprecated Node API; its warning is noise here.
process.noDeprecation = true;

class Failure extends Error {}
function fail(message) {
  throw new Failure(message);
}

// First and last message times (ns) from the MCAP summary's Statistics record.
async function mcapTimeRange(path) {
  const fh = await open(path, "r");
  try {
    const { size } = await fh.stat();
    const read = async (offset, length) => {
      const buf = Buffer.alloc(length);
      await fh.read(buf, 0, length, offset);
      return buf;
    };
    const MAGIC = Buffer.from([0x89, 0x4d, 0x43, 0x41, 0x50, 0x30, 0x0d, 0x0a]);
    // Footer record (opcode 0x02, 20-byte body) just before the closing magic.
    const FOOTER_LEN = 1 + 8 + 20;
    if (size < 8 + FOOTER_LEN + 8 || !(await read(0, 8)).equals(MAGIC)) {
      throw new Error(`${path} is not an MCAP file`);
    }
    const tail = await read(size - 8 - FOOTER_LEN, FOOTER_LEN + 8);
    if (!tail.subarray(FOOTER_LEN).equals(MAGIC) || tail[0] !== 0x02) {
      throw new Error(`${path}: no MCAP footer (truncated?)`);
    }
    const summaryStart = Number(tail.readBigUInt64LE(9));
    if (summaryStart === 0) {
      throw new Error(`${path}: no summary section`);
    }
    const summary = await read(summaryStart, size - 8 - FOOTER_LEN - summaryStart);
    for (let at = 0; at + 9 <= summary.length; ) {
      const op = summary[at];
      const len = Number(summary.readBigUInt64LE(at + 1));
      if (op === 0x0b) {
        // Statistics: message_count u64, schema_count u16, channel_count u32, attachment_count,
        // metadata_count, chunk_count u32, then message_start_time and message_end_time u64.
        const body = at + 9;
        const startAt = body + 8 + 2 + 4 * 4;
        return {
          start: summary.readBigUInt64LE(startAt),
          end: summary.readBigUInt64LE(startAt + 8),
        };
      }
      at += 9 + len;
    }
    throw new Error(`${path}: no Statistics record in the summary`);
  } finally {
    await fh.close();
  }
}

// RFC 3339 with nanoseconds, as Foxglove's `time` URL parameter takes it.
function rfc3339(ns) {
  const seconds = ns / 1_000_000_000n;
  const frac = (ns % 1_000_000_000n).toString().padStart(9, "0");
  const date = new Date(Number(seconds) * 1000).toISOString().replace(/\.\d{3}Z$/, "");
  return `${date}.${frac}Z`;
}

function listen(server) {
  return new Promise((done, failed) => {
    server.server.once("error", failed);
    server.listen(0, "127.0.0.1", () => done(server.server.address().port));
  });
}

// Pixel statistics, computed inside a blank browser page (the browser decodes the PNGs).
const ANALYSIS = `
async function pixels(b64) {
  const img = new Image();
  img.src = "data:image/png;base64," + b64;
  await img.decode();
  const c = document.createElement("canvas");
  c.width = img.width; c.height = img.height;
  const g = c.getContext("2d", { willReadFrequently: true });
  g.drawImage(img, 0, 0);
  return g.getImageData(0, 0, c.width, c.height);
}
function* inside(im, r) {
  const x0 = Math.max(0, Math.round(r.x)), y0 = Math.max(0, Math.round(r.y));
  const x1 = Math.min(im.width, Math.round(r.x + r.width)), y1 = Math.min(im.height, Math.round(r.y + r.height));
  for (let y = y0; y < y1; y++) for (let x = x0; x < x1; x++) yield 4 * (y * im.width + x);
}
window.regionStats = async (b64, rect, colours, tol, pixDiff) => {
  const im = await pixels(b64), d = im.data;
  const counts = new Map();
  let n = 0;
  for (const i of inside(im, rect)) {
    const key = (d[i] >> 4) << 8 | (d[i + 1] >> 4) << 4 | (d[i + 2] >> 4);
    counts.set(key, (counts.get(key) ?? 0) + 1);
    n++;
  }
  let bgKey = 0, best = -1;
  for (const [k, v] of counts) if (v > best) { best = v; bgKey = k; }
  // The background: mean colour of the commonest bin.
  let bg = [0, 0, 0], m = 0;
  for (const i of inside(im, rect)) {
    if (((d[i] >> 4) << 8 | (d[i + 1] >> 4) << 4 | (d[i + 2] >> 4)) === bgKey) {
      bg[0] += d[i]; bg[1] += d[i + 1]; bg[2] += d[i + 2]; m++;
    }
  }
  bg = bg.map((v) => v / m);
  let fg = 0, grey = 0, blue = 0, magenta = 0, effector = 0;
  const hits = colours.map(() => 0);
  for (const i of inside(im, rect)) {
    const hi = Math.max(d[i], d[i + 1], d[i + 2]), lo = Math.min(d[i], d[i + 1], d[i + 2]);
    if (hi >= 110 && hi - lo <= 25) grey++;
    if (d[i + 2] >= 70 && d[i + 2] - d[i] >= 40 && d[i + 2] - d[i + 1] >= 15) blue++;
    if (d[i] >= 150 && d[i + 2] >= 110 && d[i] - d[i + 1] >= 90 && d[i + 2] - d[i + 1] >= 60) magenta++;
    if (d[i] >= 100 && d[i] - d[i + 1] >= 12 && d[i + 2] - d[i + 1] >= 4 && d[i] - d[i + 2] >= 5) effector++;
    if (Math.abs(d[i] - bg[0]) + Math.abs(d[i + 1] - bg[1]) + Math.abs(d[i + 2] - bg[2]) > pixDiff) fg++;
    colours.forEach((c, k) => {
      if (Math.abs(d[i] - c[0]) <= tol && Math.abs(d[i + 1] - c[1]) <= tol && Math.abs(d[i + 2] - c[2]) <= tol) hits[k]++;
    });
  }
  return { pixels: n, distinct: counts.size, foreground: fg, foregroundFraction: fg / Math.max(n, 1), colourPixels: hits, grey, blue, magenta, effector,
           background: bg.map(Math.round) };
};
window.regionDiff = async (a, b, rect, pixDiff) => {
  const ia = await pixels(a), ib = await pixels(b);
  let n = 0, changed = 0;
  for (const i of inside(ia, rect)) {
    n++;
    if (Math.abs(ia.data[i] - ib.data[i]) + Math.abs(ia.data[i + 1] - ib.data[i + 1]) + Math.abs(ia.data[i + 2] - ib.data[i + 2]) > pixDiff) changed++;
  }
  return { pixels: n, changed, fraction: changed / Math.max(n, 1) };
};
`;

function hexColour(hex) {
  const m = /^#([0-9a-f]{2})([0-9a-f]{2})([0-9a-f]{2})$/i.exec(hex ?? "");
  return m ? [1, 2, 3].map((k) => parseInt(m[k], 16)) : undefined;
}

// Open the log at `time` and return the settled screenshot and the panel regions.
// `ready(png, regions)`, if given, ends the wait instead of the page settling (a live view).
async function capture(browser, pageUrl, panels, timeoutMs, analysis, ready) {
  const context = await browser.newContext({ viewport: { width: 1600, height: 900 }, deviceScaleFactor: 1 });
  // Close the sidebars and skip the settings tooltip, so the panels fill the window.
  await context.addInitScript(() => {
    localStorage.setItem(
      "fox.workspace",
      JSON.stringify({ state: { sidebarItem: null, leftSidebarOpen: false, rightSidebarOpen: false }, version: 0 }),
    );
    localStorage.setItem(
      "studio.profile-data",
      JSON.stringify({ onboarding: { settingsTooltipShownForPanelTypes: ["3D", "Plot"] } }),
    );
  });
  // Everything the page needs is served locally; refuse anything else at once.
  await context.route("**/*", (route) => {
    const url = new URL(route.request().url());
    if (url.hostname === "127.0.0.1" || url.protocol === "data:" || url.protocol === "blob:") {
      return route.continue();
    }
    return route.abort();
  });
  const page = await context.newPage();
  const errors = [];
  page.on("pageerror", (err) => errors.push(String(err)));
  page.on("console", (msg) => {
    if (msg.type() === "error") {
      errors.push(msg.text());
    }
  });
  await page.goto(pageUrl);
  const deadline = Date.now() + timeoutMs;
  await page.waitForFunction(() => window.polhodeViewer?.layoutLoaded || window.polhodeViewer?.error, null, {
    timeout: timeoutMs,
  });
  const pageError = await page.evaluate(() => window.polhodeViewer.error);
  if (pageError) {
    fail(`the viewer page did not start: ${pageError}`);
  }
  // Find each panel of the layout by its title, and its drawing canvas.
  const regions = await (async () => {
    for (;;) {
      const found = await page.evaluate((titles) => {
        const out = {};
        for (const tile of document.querySelectorAll(".mosaic-window")) {
          const title = titles.find((t) => tile.innerText.includes(t));
          const canvas = [...tile.querySelectorAll("canvas")].sort(
            (a, b) => b.clientWidth * b.clientHeight - a.clientWidth * a.clientHeight,
          )[0];
          if (title && canvas && canvas.clientWidth > 50 && canvas.clientHeight > 50) {
            const r = canvas.getBoundingClientRect();
            out[title] = { x: r.x, y: r.y, width: r.width, height: r.height };
          }
        }
        return out;
      }, panels.map((p) => p.title));
      if (Object.keys(found).length === panels.length) {
        return found;
      }
      if (Date.now() > deadline) {
        fail(`panels not found in the page after ${timeoutMs / 1000} s: found ${JSON.stringify(Object.keys(found))}`);
      }
      await page.waitForTimeout(500);
    }
  })();
  // Wait until loading is over: three screenshots in a row, 1.5 s apart, that (almost) agree.
  const whole = { x: 0, y: 0, width: 1600, height: 900 };
  const started = Date.now();
  let shots = [];
  for (;;) {
    await page.waitForTimeout(1500);
    shots.push((await page.screenshot()).toString("base64"));
    shots = shots.slice(-3);
    if (ready) {
      if (Date.now() - started > 6000 && (await ready(shots[shots.length - 1], regions))) {
        break;
      }
    } else if (shots.length === 3 && Date.now() - started > 6000) {
      const d1 = await analysis.evaluate(([a, b, r, p]) => window.regionDiff(a, b, r, p), [shots[0], shots[1], whole, PIXEL_DIFFERENCE]);
      const d2 = await analysis.evaluate(([a, b, r, p]) => window.regionDiff(a, b, r, p), [shots[1], shots[2], whole, PIXEL_DIFFERENCE]);
      if (d1.fraction < 1e-4 && d2.fraction < 1e-4) {
        break;
      }
    }
    if (Date.now() > deadline) {
      console.warn(`  warning: the page did not settle within ${timeoutMs / 1000} s; using the last screenshot`);
      break;
    }
  }
  // The playback time Foxglove shows (an input field in the playback bar).
  const shownTime = await page.evaluate(() => {
    const texts = [...document.querySelectorAll("input")].map((i) => i.value).concat(document.body.innerText);
    return texts.map((t) => /\d{1,2}:\d{2}:\d{2}\.\d{3} [AP]M( [A-Z]+)?/.exec(t)?.[0]).find(Boolean);
  });
  await context.close();
  return { png: shots[shots.length - 1], regions, errors, settleSeconds: (Date.now() - started) / 1000, shownTime };
}

async function main() {
  const { values: args } = parseArgs({
    options: {
      log: { type: "string" },
      live: { type: "string" },
      out: { type: "string", default: join(REPO, "docs/figures/viewing") },
      early: { type: "string", default: "10" },
      late: { type: "string", default: "120" },
      chromium: { type: "string", default: process.env.CHROMIUM ?? "/usr/bin/chromium" },
      timeout: { type: "string", default: "120" },
      orbit: { type: "boolean", default: false },
      name: { type: "string" },
      effectors: { type: "string", default: "0" },
    },
  });
  const name = args.name ?? (args.orbit ? "foxglove-orbit" : "foxglove");
  if (!args.log === !args.live) {
    fail("usage: node screenshots.mjs --log FILE.mcap [--out DIR] [--early S] [--late S], or --live ws://HOST:PORT");
  }
  const live = args.live;
  // A live run has no file: one screenshot, of whatever the connection brought.
  const logPath = live ? undefined : resolve(args.log);
  const timeoutMs = Number(args.timeout) * 1000;
  const { start, end } = live ? { start: 0n, end: 0n } : await mcapTimeRange(logPath).catch((e) => fail(e.message));
  const spanS = Number(end - start) / 1e9;
  const times = live ? { live: 0 } : { early: Number(args.early), late: Number(args.late) };
  for (const [name, t] of Object.entries(times)) {
    if (!live && !(t >= 0 && t <= spanS)) {
      fail(`--${name} ${t} s is outside the log (0 to ${spanS} s)`);
    }
  }

  // The shipped layout tells which panels to look for and the colours of their series.
  const layout = JSON.parse(await readFile(LAYOUT_FILE, "utf8"));
  const panels = Object.entries(layout.configById).map(([id, config]) => ({
    id,
    kind: id.split("!")[0],
    title: config.foxglovePanelTitle,
    series: (config.paths ?? []).map((p) => ({ path: p.value, colour: hexColour(p.color) })),
  }));
  for (const p of panels) {
    if (!p.title || p.series.some((s) => !s.colour)) {
      fail(`${LAYOUT_FILE}: panel ${p.id} needs a foxglovePanelTitle and a #rrggbb colour on every path`);
    }
  }
  // The body's 3D panel and the orbit's (by id).
  const threeD = panels.find((p) => p.kind === "3D" && !p.id.includes("orbit"));
  const orbitPanel = panels.find((p) => p.kind === "3D" && p.id.includes("orbit"));
  const plots = panels.filter((p) => p.kind === "Plot");
  if (!threeD || !orbitPanel || plots.length === 0) {
    fail(`${LAYOUT_FILE}: expected a body 3D panel, an orbit 3D panel and plot panels`);
  }

  // The repository (page, bundle, shipped layout) and the log's folder, on loopback only.
  // The log is on another origin, so expose the range headers Foxglove checks.
  const site = createServer({ root: REPO, cache: -1, showDir: false });
  const data = createServer({
    root: live ? HERE : dirname(logPath),
    cache: -1,
    showDir: false,
    cors: true,
    headers: { "Access-Control-Expose-Headers": "Accept-Ranges, Content-Range, Content-Length" },
  });
  const sitePort = await listen(site);
  const dataPort = await listen(data);
  const logUrl = live ? undefined : `http://127.0.0.1:${dataPort}/${encodeURIComponent(basename(logPath))}`;

  const browser = await chromium.launch({ executablePath: args.chromium, args: CHROMIUM_FLAGS });
  const analysis = await browser.newPage();
  await analysis.setContent("<!doctype html><title>analysis</title>");
  await analysis.addScriptTag({ content: ANALYSIS });

  await mkdir(args.out, { recursive: true });
  const shots = {};
  try {
    for (const [when, t] of Object.entries(times)) {
      const at = start + BigInt(Math.round(t * 1e9));
      const query = live
        ? new URLSearchParams({ ds: "foxglove-websocket", "ds.url": live, layoutId: LAYOUT_ID })
        : new URLSearchParams({ ds: "remote-file", "ds.url": logUrl, layoutId: LAYOUT_ID, time: rfc3339(at) });
      const pageUrl = `http://127.0.0.1:${sitePort}/scripts/viewers/foxglove/index.html?${query}`;
      const t0 = Date.now();
      // Live: wait until the body and every plotted series are drawn.
      const ready = live
        ? async (png, regions) => {
            const s3 = await analysis.evaluate(([p, r, c, tol, pd]) => window.regionStats(p, r, c, tol, pd), [
              png, regions[threeD.title], [], COLOUR_TOLERANCE, PIXEL_DIFFERENCE,
            ]);
            if (s3.grey < MIN_BODY_PIXELS_LIVE) return false;
            for (const p of plots) {
              const sp = await analysis.evaluate(([pn, r, c, tol, pd]) => window.regionStats(pn, r, c, tol, pd), [
                png, regions[p.title], p.series.map((x) => x.colour), COLOUR_TOLERANCE, PIXEL_DIFFERENCE,
              ]);
              if (sp.colourPixels.some((n) => n < MIN_SERIES_PIXELS)) return false;
            }
            return true;
          }
        : undefined;
      const shot = await capture(browser, pageUrl, panels, timeoutMs, analysis, ready);
      const file = join(args.out, `${name}-${when}.png`);
      await writeFile(file, Buffer.from(shot.png, "base64"));
      console.log(
        `${when}: ${live ? live : `t = ${t} s (${rfc3339(at)})`}, shown ${shot.shownTime ?? "?"}, ${((Date.now() - t0) / 1000).toFixed(1)} s` +
          ` (settled after ${shot.settleSeconds.toFixed(1)} s) -> ${file}`,
      );
      for (const e of shot.errors) {
        console.log(`  page error: ${e.slice(0, 300)}`);
      }
      shots[when] = shot;
    }

    // The checks.
    const problems = [];
    const stats = (shot, title, colours) =>
      analysis.evaluate(([png, r, c, tol, pd]) => window.regionStats(png, r, c, tol, pd), [
        shot.png,
        shot.regions[title],
        colours,
        COLOUR_TOLERANCE,
        PIXEL_DIFFERENCE,
      ]);
    for (const [name, shot] of Object.entries(shots)) {
      // (a) The 3D panel is not blank.
      const s3 = await stats(shot, threeD.title, []);
      const ok3 = s3.distinct >= MIN_DISTINCT_COLOURS && s3.foregroundFraction >= MIN_FOREGROUND_FRACTION;
      console.log(
        `  [${ok3 ? "ok" : "FAIL"}] ${name} 3D panel not blank: ${s3.distinct} distinct colours (>= ${MIN_DISTINCT_COLOURS}),` +
          ` ${s3.foreground}/${s3.pixels} = ${(100 * s3.foregroundFraction).toFixed(2)} % off the background` +
          ` rgb(${s3.background}) (>= ${100 * MIN_FOREGROUND_FRACTION} %)`,
      );
      if (!ok3) problems.push(`${name}: the 3D panel is blank`);
      // (a) The body itself (light grey, from /scene) is drawn, not only the grid and axes.
      const minBody = args.orbit ? MIN_BODY_PIXELS_ORBIT : live ? MIN_BODY_PIXELS_LIVE : MIN_BODY_PIXELS;
      const okBody = s3.grey >= minBody;
      console.log(`  [${okBody ? "ok" : "FAIL"}] ${name} body drawn: ${s3.grey} light grey pixels (>= ${minBody})`);
      if (!okBody) problems.push(`${name}: no body in the 3D panel (is /scene drawn?)`);
      // (a) With --effectors: the effectors (discs of rotors and wheels) are drawn.
      const minEffector = Number(args.effectors);
      if (minEffector > 0) {
        const okEffector = s3.effector >= minEffector;
        console.log(`  [${okEffector ? "ok" : "FAIL"}] ${name} effectors drawn: ${s3.effector} red pixels (>= ${minEffector})`);
        if (!okEffector) problems.push(`${name}: no effector (red) in the 3D panel`);
      }
      // (d) With --orbit: the Earth, the orbit path and the spacecraft marker are drawn.
      if (args.orbit) {
        const so = await stats(shot, orbitPanel.title, [PATH_COLOUR]);
        const okBlank = so.distinct >= MIN_DISTINCT_COLOURS && so.foregroundFraction >= MIN_FOREGROUND_FRACTION;
        const okEarth = so.blue >= MIN_EARTH_PIXELS;
        const okPath = so.colourPixels[0] >= MIN_PATH_PIXELS;
        const okMarker = so.magenta >= MIN_MARKER_PIXELS;
        console.log(
          `  [${okBlank && okEarth && okPath && okMarker ? "ok" : "FAIL"}] ${name} orbit panel: ${so.distinct} colours,` +
            ` ${(100 * so.foregroundFraction).toFixed(2)} % off the background; Earth ${so.blue} blue pixels` +
            ` (>= ${MIN_EARTH_PIXELS}), path ${so.colourPixels[0]} cyan (>= ${MIN_PATH_PIXELS}),` +
            ` marker ${so.magenta} magenta (>= ${MIN_MARKER_PIXELS})`,
        );
        if (!okBlank) problems.push(`${name}: the orbit panel is blank`);
        if (!okEarth) problems.push(`${name}: no Earth in the orbit panel (is /earth drawn?)`);
        if (!okPath) problems.push(`${name}: no orbit path in the orbit panel (is /orbit_scene drawn?)`);
        if (!okMarker) problems.push(`${name}: no spacecraft marker in the orbit panel`);
      }
      // (a, c) Each plot is drawn, with every series present (with --orbit: not blank).
      for (const p of plots) {
        const sp = await stats(shot, p.title, p.series.map((s) => s.colour));
        const okBlank = sp.distinct >= MIN_DISTINCT_COLOURS && sp.foregroundFraction >= MIN_FOREGROUND_FRACTION;
        const perSeries = p.series.map((s, k) => `${s.path.replace("/telemetry.", "")} ${sp.colourPixels[k]}`).join(", ");
        const okSeries = sp.colourPixels.every((n) => n >= MIN_SERIES_PIXELS);
        const mark = okBlank && okSeries ? "ok" : !okBlank ? "FAIL" : args.orbit ? "info" : "FAIL";
        console.log(
          `  [${mark}] ${name} plot "${p.title}": ${sp.distinct} colours,` +
            ` ${(100 * sp.foregroundFraction).toFixed(2)} % off the background; series pixels: ${perSeries}` +
            ` (each >= ${MIN_SERIES_PIXELS})`,
        );
        if (!okBlank) problems.push(`${name}: plot "${p.title}" is blank`);
        if (!okSeries && !args.orbit) problems.push(`${name}: plot "${p.title}" misses a series (${perSeries})`);
      }
    }
    if (live) {
      if (problems.length > 0) {
        fail(problems.join("; "));
      }
      console.log(`PASS: Foxglove connected to the live run ${live} with the shipped layout; 3D panel and plots drawn`);
      return;
    }
    // (b) The body moved: the 3D panel differs between the two times.
    const r = shots.early.regions[threeD.title];
    const d = await analysis.evaluate(([a, b, rr, pd]) => window.regionDiff(a, b, rr, pd), [
      shots.early.png,
      shots.late.png,
      r,
      PIXEL_DIFFERENCE,
    ]);
    const okMoved = d.fraction >= MIN_3D_CHANGE_FRACTION;
    console.log(
      `  [${okMoved ? "ok" : args.orbit ? "info" : "FAIL"}] 3D panel differs between early and late: ${d.changed}/${d.pixels} = ` +
        `${(100 * d.fraction).toFixed(2)} % of pixels (>= ${100 * MIN_3D_CHANGE_FRACTION} %)`,
    );
    // (In orbit the body turns once per orbit about the orbit normal: a short run may not move
    // it enough; the orbit panel's change is checked instead.)
    if (!okMoved && !args.orbit) problems.push("the 3D panel is the same at both times (the body did not move)");
    if (args.orbit) {
      const ro = shots.early.regions[orbitPanel.title];
      const dO = await analysis.evaluate(([a, b, rr, pd]) => window.regionDiff(a, b, rr, pd), [
        shots.early.png,
        shots.late.png,
        ro,
        PIXEL_DIFFERENCE,
      ]);
      const okOrbitMoved = dO.fraction >= MIN_3D_CHANGE_FRACTION;
      console.log(
        `  [${okOrbitMoved ? "ok" : "FAIL"}] orbit panel differs between early and late: ${dO.changed}/${dO.pixels} = ` +
          `${(100 * dO.fraction).toFixed(2)} % of pixels (>= ${100 * MIN_3D_CHANGE_FRACTION} %)`,
      );
      if (!okOrbitMoved) problems.push("the orbit panel is the same at both times (the spacecraft did not move)");
    }

    if (problems.length > 0) {
      fail(problems.join("; "));
    }
    console.log(
      `PASS: Foxglove opened the log with the shipped layout; 3D panel${args.orbit ? "s (body and orbit)" : ""} and plots drawn at both times`,
    );
  } finally {
    await browser.close();
    site.close();
    data.close();
  }
}

try {
  await main();
} catch (err) {
  console.error(`FAIL: ${err instanceof Failure ? err.message : err.stack ?? err}`);
  process.exitCode = 1;
}

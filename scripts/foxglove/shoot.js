// Takes one screenshot of Foxglove Studio showing a running OSCAR system, for
// scripts/foxglove_screenshots.sh (which installs what this needs and boots the system).
//
//   node shoot.js --npm DIR --studio DIR --layout FILE --ws URL --out PNG
//                 [--expect TEXT]... [--width 1280] [--height 800] [--timeout-s 90] [--settle-s 15]
//
// Serves the host page (host.html, host.js beside this file), React, the studio bundle and the
// layout from 127.0.0.1, opens it in Debian's chromium (headless, WebGL in software) and waits
// until Foxglove's topic list counts messages on every topic the layout's panels read and each
// --expect text shows on the page; then it closes that list, lets the plots fill for --settle-s
// seconds and writes the PNG.
// The browser may reach 127.0.0.1 only: every other host name fails to resolve and every other
// request is aborted (and reported).
"use strict";
const fs = require("fs");
const http = require("http");
const path = require("path");

function parseArgs(argv) {
  const args = { expect: [], width: 1280, height: 800, timeoutS: 90, settleS: 15, chromium: "/usr/bin/chromium" };
  for (let i = 0; i < argv.length; i += 2) {
    const [flag, value] = [argv[i], argv[i + 1]];
    if (value === undefined) throw new Error(`${flag}: needs a value`);
    switch (flag) {
      case "--npm": args.npm = value; break;
      case "--studio": args.studio = value; break;
      case "--layout": args.layout = value; break;
      case "--ws": args.ws = value; break;
      case "--out": args.out = value; break;
      case "--expect": args.expect.push(value); break;
      case "--width": args.width = Number(value); break;
      case "--height": args.height = Number(value); break;
      case "--timeout-s": args.timeoutS = Number(value); break;
      case "--settle-s": args.settleS = Number(value); break;
      case "--chromium": args.chromium = value; break;
      default: throw new Error(`unknown option ${flag}`);
    }
  }
  for (const name of ["npm", "studio", "layout", "ws", "out"]) {
    if (!args[name]) throw new Error(`--${name} is required`);
  }
  for (const name of ["npm", "studio", "layout", "out"]) args[name] = path.resolve(args[name]);
  if (!/^ws:\/\/127\.0\.0\.1:\d+$/.test(args.ws)) {
    throw new Error(`--ws ${args.ws}: must be ws://127.0.0.1:PORT (the browser talks to this machine only)`);
  }
  return args;
}

const contentTypes = { ".html": "text/html", ".js": "text/javascript", ".json": "application/json",
  ".wasm": "application/wasm", ".png": "image/png", ".svg": "image/svg+xml", ".css": "text/css",
  ".woff2": "font/woff2", ".woff": "font/woff", ".ttf": "font/ttf" };

// URL prefix -> directory (or a single file) served from 127.0.0.1.
function serve(routes) {
  const server = http.createServer((req, res) => {
    const url = new URL(req.url, "http://127.0.0.1");
    for (const [prefix, target] of routes) {
      if (url.pathname === prefix || (prefix.endsWith("/") && url.pathname.startsWith(prefix))) {
        const file = prefix.endsWith("/")
          ? path.join(target, path.normalize(url.pathname.slice(prefix.length)).replace(/^(\.\.[/\\])+/, ""))
          : target;
        fs.readFile(file, (err, data) => {
          if (err) { res.writeHead(404); res.end(); return; }
          res.writeHead(200, { "Content-Type": contentTypes[path.extname(file)] ?? "application/octet-stream" });
          res.end(data);
        });
        return;
      }
    }
    res.writeHead(404);
    res.end();
  });
  return new Promise((resolve) => server.listen(0, "127.0.0.1", () => resolve(server)));
}

// The topics a layout's panels read (every string value naming a topic, and the keys of a 3D
// panel's "topics"), so that we can wait for each of them to have had messages.
function layoutTopics(layout) {
  const topics = new Set();
  const visit = (value, key) => {
    if (typeof value === "string") {
      const m = value.match(/^"?((?:oscar|foxglove)\/[^"\s.{[]+)"?/);
      if (m && /topic|path|value/i.test(key ?? "")) topics.add(m[1]);
    } else if (Array.isArray(value)) {
      value.forEach((v) => visit(v, key));
    } else if (value && typeof value === "object") {
      for (const [k, v] of Object.entries(value)) {
        if (k === "topics" && v && typeof v === "object" && !Array.isArray(v)) {
          for (const [t, cfg] of Object.entries(v)) if (cfg && cfg.visible !== false) topics.add(t);
        }
        visit(v, k);
      }
    }
  };
  visit(layout.configById);
  return [...topics];
}

// The problems Foxglove lists in the data source sidebar (its "Problems" tab), one a line.
async function foxgloveProblems(page) {
  const [tab] = await page.$$("xpath/.//button[@role='tab'][contains(., 'Problems')]");
  if (!tab) return [];
  await tab.click();
  await new Promise((r) => setTimeout(r, 500));
  const lines = (await page.evaluate(() => document.body.innerText)).split("\n");
  return [...new Set(lines.filter((l) => /^(Failed|Error|Unsupported|No |Unable)/.test(l.trim())))];
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

async function main() {
  const args = parseArgs(process.argv.slice(2));
  const puppeteer = require(path.join(args.npm, "node_modules", "puppeteer-core"));
  const layout = JSON.parse(fs.readFileSync(args.layout, "utf8"));
  const wanted = layoutTopics(layout);
  const here = __dirname;
  const server = await serve([
    ["/host.html", path.join(here, "host.html")],
    ["/host.js", path.join(here, "host.js")],
    ["/layout.json", args.layout],
    ["/react/", path.join(args.npm, "node_modules", "react", "umd")],
    ["/react-dom/", path.join(args.npm, "node_modules", "react-dom", "umd")],
    ["/studio/", args.studio],
  ]);
  const origin = `http://127.0.0.1:${server.address().port}`;
  const profile = fs.mkdtempSync(path.join(require("os").tmpdir(), "oscar-foxglove-shot-"));
  const browser = await puppeteer.launch({
    executablePath: args.chromium,
    headless: true,
    userDataDir: profile,
    defaultViewport: { width: args.width, height: args.height },
    args: [
      "--no-sandbox", // runs as root in a container
      "--no-first-run", "--no-default-browser-check", "--disable-sync",
      "--disable-component-update", "--disable-background-networking", "--disable-default-apps",
      "--disable-domain-reliability", "--disable-breakpad", "--disable-client-side-phishing-detection",
      "--disable-features=Translate,OptimizationHints,MediaRouter,AutofillServerCommunication,CertificateTransparencyComponentUpdater",
      "--metrics-recording-only", "--password-store=basic", "--use-mock-keychain",
      "--host-resolver-rules=MAP * ~NOTFOUND, EXCLUDE 127.0.0.1",
      "--use-gl=angle", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist",
      `--window-size=${args.width},${args.height}`,
    ],
  });
  const refused = [];
  const problems = [];
  try {
    const page = await browser.newPage();
    page.on("console", (msg) => {
      if (msg.type() === "error") problems.push(msg.text());
    });
    page.on("pageerror", (error) => problems.push(String(error)));
    page.on("response", (response) => {
      if (response.status() >= 400) problems.push(`${response.status()} for ${response.url()}`);
    });
    await page.setRequestInterception(true);
    page.on("request", (request) => {
      const url = new URL(request.url());
      if (url.protocol === "data:" || url.protocol === "blob:" || url.hostname === "127.0.0.1") {
        request.continue();
      } else {
        refused.push(request.url());
        request.abort();
      }
    });
    const query = new URLSearchParams({ ds: "foxglove-websocket", "ds.url": args.ws, layoutId: "oscar" });
    await page.goto(`${origin}/host.html?${query}`, { waitUntil: "load" });

    // The data source sidebar lists every topic with the messages it received and their rate
    // ("—" while no panel subscribes); read it until each topic of the layout has messages.
    const deadline = Date.now() + args.timeoutS * 1000;
    let counts;
    for (;;) {
      const lines = (await page.evaluate(() => document.body.innerText)).split("\n").map((l) => l.trim());
      counts = Object.fromEntries(wanted.map((t) => {
        const at = lines.indexOf(t);
        return [t, at >= 0 ? Number(lines[at + 2]) || 0 : 0];
      }));
      const text = lines.join("\n");
      const missing = [
        ...wanted.filter((t) => counts[t] === 0).map((t) => `messages of ${t}`),
        ...args.expect.filter((e) => !text.includes(e)).map((e) => `the text '${e}'`),
      ];
      if (missing.length === 0) break;
      if (Date.now() > deadline) {
        await page.screenshot({ path: args.out + ".failed.png" });
        const shown = await foxgloveProblems(page);
        throw new Error(`after ${args.timeoutS} s still no ${missing.join(", ")} (page as it was: ` +
          `${args.out}.failed.png; Foxglove's problems: ${shown.join("; ") || "none"})`);
      }
      await sleep(500);
    }
    // Every panel has data: close the sidebar (its button toggles it), let the plots fill.
    await page.click('[data-sidebar-key="connection"]');
    await sleep(args.settleS * 1000);
    await page.screenshot({ path: args.out });
    await page.click('[data-sidebar-key="connection"]'); // open again to read its problems
    await sleep(1000);
    const foxglove = await foxgloveProblems(page);
    console.log(JSON.stringify({
      out: args.out,
      messages_when_complete: counts,
      refused_requests: refused,
      page_errors: problems.filter((p) => !p.startsWith("Player problem")),
      foxglove_problems: foxglove.length,
      foxglove_problems_not_on_oscar_channels: foxglove.filter((p) => !/ on oscar\//.test(p)),
    }, null, 1));
  } finally {
    await browser.close();
    server.close();
    fs.rmSync(profile, { recursive: true, force: true });
  }
}

main().catch((error) => {
  console.error(`foxglove shot: ${error.message}`);
  process.exit(1);
});

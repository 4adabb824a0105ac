// Mounts Foxglove Studio's App for scripts/foxglove_screenshots.sh. The layout comes from
// /layout.json (one of docs/foxglove/*.json), the connection from the page's URL
// (?ds=foxglove-websocket&ds.url=ws://127.0.0.1:8765&layoutId=oscar), read by the App itself.
"use strict";

// Settings kept in memory: nothing to sign in to, no telemetry, no update checks, no dialogs.
class MemorySettings {
  constructor(values) {
    this.values = new Map(Object.entries(values));
    this.listeners = new Map();
  }
  get(key) {
    return this.values.get(key);
  }
  async set(key, value) {
    this.values.set(key, value);
    for (const listener of this.listeners.get(key) ?? []) listener(value);
  }
  addChangeListener(key, listener) {
    if (!this.listeners.has(key)) this.listeners.set(key, new Set());
    this.listeners.get(key).add(listener);
  }
  removeChangeListener(key, listener) {
    this.listeners.get(key)?.delete(listener);
  }
}

// Layouts kept in memory, the one to show already stored under the id the URL names.
class MemoryLayouts {
  constructor(layout) {
    this.layouts = new Map([[layout.id, layout]]);
  }
  async list() {
    return [...this.layouts.values()];
  }
  async get(_namespace, id) {
    return this.layouts.get(id);
  }
  async put(_namespace, layout) {
    this.layouts.set(layout.id, layout);
    return layout;
  }
  async delete(_namespace, id) {
    this.layouts.delete(id);
  }
  async importLayouts() {}
}

// Foxglove Studio 1.48 (the newest @foxglove/studio-base on npm) calls its image panel
// "ImageViewPanel"; its panel "Image", the one later versions and the committed layouts use, was
// an experiment there that draws nothing without a CameraInfo topic. Both read `cameraTopic`
// (the layouts set it beside the later `imageMode.imageTopic`), so the host renames the panels.
function imagePanelsFor148(layoutData) {
  const rename = (id) => (id.startsWith("Image!") ? "ImageViewPanel!" + id.slice("Image!".length) : id);
  const tree = (node) =>
    typeof node === "string" ? rename(node) : { ...node, first: tree(node.first), second: tree(node.second) };
  const configById = Object.fromEntries(Object.entries(layoutData.configById).map(([id, c]) => [rename(id), c]));
  return { ...layoutData, configById, layout: tree(layoutData.layout) };
}

async function main() {
  const studio = window; // the UMD bundle put its exports here
  const layoutData = imagePanelsFor148(await (await fetch("/layout.json")).json());
  // The panels' one-time "open settings" hints were seen: they would cover the panels.
  localStorage.setItem(
    "studio.profile-data",
    JSON.stringify({ onboarding: { settingsTooltipShownForPanelTypes: Object.keys(layoutData.configById).map((id) => id.split("!")[0]) } }),
  );
  const now = new Date().toISOString();
  const layout = {
    id: "oscar",
    name: "OSCAR",
    permission: "CREATOR_WRITE",
    baseline: { data: layoutData, savedAt: now },
    working: undefined,
    syncInfo: undefined,
  };
  const settings = new MemorySettings({
    colorScheme: "dark",
    "telemetry.telemetryEnabled": false,
    "telemetry.crashReportingEnabled": false,
    "updates.enabled": false,
    hideSignInPrompt: true,
    launchPreference: "web",
    "ui.open-dialog-startup": false,
    language: "en",
  });
  await studio.initI18n();
  const app = React.createElement(studio.App, {
    deepLinks: [window.location.href],
    appConfiguration: settings,
    dataSources: [new studio.FoxgloveWebSocketDataSourceFactory()],
    layoutStorage: new MemoryLayouts(layout),
    extensionLoaders: [],
    enableLaunchPreferenceScreen: false,
    enableGlobalCss: true,
  });
  ReactDOM.render(app, document.getElementById("root"));
}

main().catch((error) => {
  console.error("host.js: " + (error && error.stack ? error.stack : error));
});

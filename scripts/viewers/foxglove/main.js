// Starts Foxglove Studio with in-memory settings and a layout storage that holds exactly the
// shipped layout file, docs/viewers/polhode.foxglove-layout.json.
"use strict";

// The shipped layout, relative to this page (the repository root must be served).
const LAYOUT_URL = "../../../docs/viewers/polhode.foxglove-layout.json";
const LAYOUT_ID = "polhode";

// State for scripts driving the page (screenshots.mjs reads it).
window.polhodeViewer = { layoutLoaded: false, error: undefined };

// Settings kept in memory only; nothing touches the browser's storage or the network.
function memoryConfiguration(initial) {
  const values = new Map(Object.entries(initial));
  const listeners = new Map();
  return {
    get: (key) => values.get(key),
    async set(key, value) {
      values.set(key, value);
      for (const cb of listeners.get(key) ?? []) {
        cb(value);
      }
    },
    addChangeListener(key, cb) {
      if (!listeners.has(key)) {
        listeners.set(key, new Set());
      }
      listeners.get(key).add(cb);
    },
    removeChangeListener(key, cb) {
      listeners.get(key)?.delete(cb);
    },
  };
}

// Layouts by namespace, in memory; the shipped layout is put into every namespace asked for.
function memoryLayoutStorage(seed) {
  const spaces = new Map();
  const space = (ns) => {
    if (!spaces.has(ns)) {
      spaces.set(ns, new Map(seed.map((l) => [l.id, structuredClone(l)])));
    }
    return spaces.get(ns);
  };
  return {
    list: async (ns) => [...space(ns).values()],
    get: async (ns, id) => space(ns).get(id),
    async put(ns, layout) {
      space(ns).set(layout.id, layout);
      return layout;
    },
    async delete(ns, id) {
      space(ns).delete(id);
    },
    async importLayouts({ fromNamespace, toNamespace }) {
      for (const layout of space(fromNamespace).values()) {
        space(toNamespace).set(layout.id, layout);
      }
    },
  };
}

async function main() {
  const response = await fetch(LAYOUT_URL, { cache: "no-store" });
  if (!response.ok) {
    throw new Error(`cannot load the layout ${LAYOUT_URL}: HTTP ${response.status}`);
  }
  const data = await response.json();
  const layout = {
    id: LAYOUT_ID,
    name: "polhode",
    permission: "CREATOR_WRITE",
    baseline: { data, savedAt: new Date(0).toISOString() },
    working: undefined,
    syncInfo: undefined,
  };
  window.polhodeViewer.layoutData = data;

  // Exports of the UMD bundle land on window.
  window.overwriteFetch();
  await window.waitForFonts();
  await window.initI18n();

  const app = React.createElement(window.App, {
    deepLinks: [window.location.href],
    appConfiguration: memoryConfiguration({
      colorScheme: "dark",
      timezone: "UTC",
      "telemetry.telemetryEnabled": false,
      "telemetry.crashReportingEnabled": false,
      "updates.enabled": false,
      hideSignInPrompt: true,
    }),
    layoutStorage: memoryLayoutStorage([layout]),
    // A log file (ds=remote-file), or a live run (ds=foxglove-websocket, `polhode run --live`).
    dataSources: [
      new window.RemoteDataSourceFactory(),
      new window.McapLocalDataSourceFactory(),
      new window.FoxgloveWebSocketDataSourceFactory(),
    ],
    extensionLoaders: [],
    enableLaunchPreferenceScreen: false,
  });
  ReactDOM.render(app, document.getElementById("root"));
  window.polhodeViewer.layoutLoaded = true;
}

main().catch((err) => {
  window.polhodeViewer.error = String(err && err.stack ? err.stack : err);
  console.error(err);
});

// The page's panes: the splitter between the editor and the views (dragged, or moved with the
// arrow keys), where the results go (beside the views, under the editor; or under both at full
// width), and the views on the whole screen. The choices are kept in the browser's storage.

const $ = (id) => document.getElementById(id);
const KEY = "cadkg.layout";

function saved() {
  try {
    return JSON.parse(localStorage.getItem(KEY) || "{}");
  } catch (err) {
    return {};
  }
}

function keep(change) {
  const layout = { ...saved(), ...change };
  localStorage.setItem(KEY, JSON.stringify(layout));
}

/** Put the results beside the views ("beside") or under the editor at full width ("under"). */
export function placeResults(place) {
  const where = place === "under" ? "under" : "beside";
  document.body.dataset.results = where;
  $("results-place").value = where;
  keep({ results: where });
}

/** Give the editor's column `pixels` of the page's width (within what both panes need). */
export function splitAt(pixels) {
  const main = $("panes");
  const width = main.clientWidth;
  const left = Math.round(Math.min(Math.max(pixels, 320), width - 380));
  main.style.setProperty("--left", `${left}px`);
  keep({ left });
  return left;
}

function installSplitter() {
  const splitter = $("splitter");
  const main = $("panes");
  const padding = () => parseFloat(getComputedStyle(main).paddingLeft) || 0;
  splitter.addEventListener("pointerdown", (event) => {
    splitter.setPointerCapture(event.pointerId);
    splitter.classList.add("dragging");
  });
  splitter.addEventListener("pointermove", (event) => {
    if (!splitter.classList.contains("dragging")) return;
    splitAt(event.clientX - main.getBoundingClientRect().left - padding());
  });
  const stop = () => splitter.classList.remove("dragging");
  splitter.addEventListener("pointerup", stop);
  splitter.addEventListener("pointercancel", stop);
  splitter.addEventListener("keydown", (event) => {
    const step = event.key === "ArrowLeft" ? -40 : event.key === "ArrowRight" ? 40 : 0;
    if (step) splitAt($("editor-pane").offsetWidth + step);
  });
}

/** The views on the whole screen, or back; a browser that refuses full screen gets the window. */
export async function toggleFullScreen() {
  const pane = $("view-pane");
  if (document.fullscreenElement || pane.classList.contains("maximised")) {
    pane.classList.remove("maximised");
    if (document.fullscreenElement) await document.exitFullscreen();
  } else {
    try {
      await pane.requestFullscreen();
    } catch (err) {
      pane.classList.add("maximised");
    }
  }
  const full = Boolean(document.fullscreenElement) || pane.classList.contains("maximised");
  $("cell-fullscreen").textContent = full ? "Leave full screen" : "Full screen";
  pane.dataset.full = String(full);
}

export function installLayout() {
  const layout = saved();
  placeResults(layout.results);
  if (layout.left) $("panes").style.setProperty("--left", `${layout.left}px`);
  $("results-place").addEventListener("change", () => placeResults($("results-place").value));
  installSplitter();
  $("cell-fullscreen").addEventListener("click", () => toggleFullScreen());
  document.addEventListener("fullscreenchange", () => {
    const full = Boolean(document.fullscreenElement);
    $("cell-fullscreen").textContent = full ? "Leave full screen" : "Full screen";
    $("view-pane").dataset.full = String(full);
  });
  document.addEventListener("keydown", (event) => {
    if (event.key === "Escape" && $("view-pane").classList.contains("maximised")) toggleFullScreen();
  });
}

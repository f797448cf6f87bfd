// mandelreel explore: the page. It holds the view (a frame, and values the
// user changed but has not keyed) and asks the server for renders, picks
// and edits; the timeline's text lives on the server.
"use strict";

const TOKEN = document.querySelector('meta[name="token"]').content;
const $ = (id) => document.getElementById(id);

const page = {
  state: null,          // the timeline as the server shows it (/api/state)
  values: {},           // every parameter's value at this frame
  iterations: null,     // this frame's count, as /api/iterations shows it
  frame: 0,
  overrides: {},        // parameter -> numbers, laid over the tracks' values
  typed: {},            // parameter -> per component, digits typed past f64's (or undefined)
  digits: {},           // parameter -> the strings of digits this frame's point is held in
  selected: null,       // {track, index} of the selected key
  serial: 0,            // the latest view asked for; older renders are dropped
  dragging: false,
  playing: false,
  playCache: new Map(), // frame -> blob URL of its playback frame
  pickCache: null,      // {x, y, serial, hit} for a burst of wheel events
  shown: null,          // the PNG shown, as the server sent it
};

// ---- talking to the server ------------------------------------------------

async function api(path, body) {
  const init = { headers: { "x-mandelreel-token": TOKEN } };
  if (body !== undefined) {
    init.method = "POST";
    init.headers["content-type"] = "application/json";
    init.body = JSON.stringify(body);
  }
  const response = await fetch(path, init);
  if (!response.ok) {
    const error = new Error(await response.text());
    error.status = response.status;
    throw error;
  }
  return response;
}

function currentView(withOverrides = true) {
  const overrides = {};
  if (withOverrides) for (const name of Object.keys(page.overrides)) overrides[name] = sent(name);
  const view = { frame: page.frame, overrides };
  const size = $("size").value.trim();
  if (size) view.size = size;
  const samples = parseInt($("samples").value, 10);
  if (samples > 0) view.samples = samples;
  return view;
}

function say(text) { $("message").textContent = text; }

// An error replaces the last status line, which no longer holds beside it.
function alertShown(text) {
  $("alert").textContent = text || "";
  $("alert").hidden = !text;
  if (text) say("");
}

// ---- the timeline ---------------------------------------------------------

async function loadState(state) {
  page.state = state || await (await api("/api/state")).json();
  page.playCache.clear();
  const s = page.state;
  $("name").textContent = s.name;
  $("dirty").hidden = !s.dirty;
  $("frame").max = $("slider").max = s.frames - 1;
  if (page.frame > s.frames - 1) page.frame = s.frames - 1;
  $("plan").textContent = s.plan.join("\n");
  $("command").textContent = s.command;
  $("text").textContent = s.text;
  page.selected = reselected(page.selected);
  buildControls();
  await showFrame(page.frame);
}

function trackNamed(name) { return page.state.tracks.find((t) => t.name === name); }

async function showFrame(frame) {
  const asked = frame | 0;
  frame = Math.max(0, Math.min(page.state.frames - 1, asked));
  if (frame !== asked) say(`The film has frames 0 to ${page.state.frames - 1}: showing frame ${frame}.`);
  page.frame = frame;
  $("frame").value = $("slider").value = frame;
  $("time").textContent = `t = ${(frame / page.state.fps).toFixed(3)} s of ${(page.state.frames / page.state.fps).toFixed(2)} s`;
  const serial = page.valuesAsked = (page.valuesAsked || 0) + 1;
  const [values, iterations, digits] = await Promise.all([
    api(`/api/values?frame=${frame}`).then((r) => r.json()),
    api(`/api/iterations?frame=${frame}`).then((r) => r.json()),
    api(`/api/digits?frame=${frame}`).then((r) => r.json()),
  ]);
  if (serial !== page.valuesAsked) return;  // asked again meanwhile
  page.values = values;
  page.digits = digits;
  page.iterations = iterations;
  drawStrip();
  fillControls();
  refresh();
}

// ---- rendering, progressively ----------------------------------------------

// Renders the view in stages, each shown as it arrives; a newer view
// makes the server give up this one's stages.
async function refresh() {
  const serial = ++page.serial;
  const view = currentView();
  showChanges();
  try {
    let shown = await stage(view, "quick", null, serial);
    if (!shown || page.dragging) return;
    if ((view.samples || page.state.samples) > 1) {
      rendering(view, "full", serial);
      const full = await stage(view, "full", shown.generation, serial);
      if (!full) return;
    }
    rendering(view, "final", serial);
    await stage(view, "final", shown.generation, serial);
  } catch (error) {
    if (serial === page.serial) alertShown(error.message);
  }
}

// The full-size stages take seconds at large sizes: the bar starts again
// and the overlay says what is coming (the server's events fill the bar).
function rendering(view, name, serial) {
  if (serial !== page.serial) return;
  $("progress").value = 0;
  const size = view.size || `${page.state.width}x${page.state.height}`;
  $("overlay").textContent += ` · rendering ${name} at ${size}…`;
}

async function stage(view, name, generation, serial) {
  if (serial !== page.serial) return null;
  let response;
  try {
    response = await api("/api/render", { view, stage: name, generation });
  } catch (error) {
    if (error.status === 409) return null;  // a newer view took over
    throw error;
  }
  const blob = await response.blob();
  if (serial !== page.serial || page.playing) return null;
  const img = $("view");
  page.shown = blob;
  const old = img.src;
  img.src = URL.createObjectURL(blob);
  if (old.startsWith("blob:")) URL.revokeObjectURL(old);
  const size = response.headers.get("x-size");
  const samples = response.headers.get("x-samples");
  const seconds = response.headers.get("x-seconds");
  img.dataset.stage = name;
  img.dataset.frame = view.frame;
  img.dataset.serial = serial;
  img.dataset.size = size;
  $("overlay").textContent = `frame ${view.frame} · ${name} · ${size} · ${samples} sample(s) · ${seconds} s`;
  // A quick stage is small on purpose: only a full-size one is remarked on.
  img.onload = name === "quick" ? null : () => enlarged(img);
  if (name === "final") { $("progress").value = 1; alertShown(""); }
  return { generation: Number(response.headers.get("x-generation")) };
}

// A small frame stretched to the page's width looks soft: say so, and
// where the pixels come from.
function enlarged(img) {
  // The picture is fitted inside the element (object-fit: contain).
  const times = Math.min(img.clientWidth / img.naturalWidth, img.clientHeight / img.naturalHeight);
  if (times > 1.5 && !$("overlay").textContent.includes("shown ×")) {
    $("overlay").textContent += ` · shown ×${times.toFixed(1)}: Size (right) sets the pixels`;
  }
}

// While a drag or the wheel moves the view, only quick stages are asked for,
// one at a time: the newest view when the last one comes back.
let moving = null;
function refreshSoon() {
  if (moving) { moving.again = true; return; }
  moving = { again: false };
  const serial = ++page.serial;
  showChanges();
  stage(currentView(), "quick", null, serial)
    .catch((error) => alertShown(error.message))
    .finally(() => {
      const again = moving.again;
      moving = null;
      if (again) refreshSoon();
      else if (!page.dragging) refresh();
    });
}

// ---- the camera -------------------------------------------------------------

const sub = (a, b) => a.map((v, i) => v - b[i]);
const add = (a, b) => a.map((v, i) => v + b[i]);
const scale = (a, k) => a.map((v) => v * k);
const dot = (a, b) => a.reduce((s, v, i) => s + v * b[i], 0);
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const norm = (a) => scale(a, 1 / Math.hypot(...a));

function value(name) { return page.overrides[name] || page.values[name]; }

function change(name, numbers) {
  page.overrides[name] = numbers.map((v) => Number(v.toPrecision(15)));
  delete page.typed[name];
}

// A value as the server gets it: the numbers, with the digits typed for
// components that f64 would round (a deep target's), as strings.
function sent(name, numbers = page.overrides[name]) {
  const typed = page.typed[name];
  return typed ? numbers.map((v, i) => typed[i] ?? v) : numbers;
}

// Significant digits of a number as typed: more than 15 and f64 may round it.
function significant(text) {
  const mantissa = text.replace(/^[+-]/, "").split(/[eE]/)[0].replace(".", "");
  return mantissa.replace(/^0+/, "").replace(/0+$/, "").length;
}

// What an HTML number field holds as written (it blanks "+0.5" and "5.").
const NUMBER_TEXT = /^-?(\d+(\.\d+)?|\.\d+)([eE][+-]?\d+)?$/;

// Component i of the strings of digits this frame's point `name` is held
// in, where a number field can show it.
function held(name, i) {
  const text = (page.digits[name] || [])[i];
  return text !== undefined && NUMBER_TEXT.test(text) ? text : undefined;
}

// Component text `text` (i of point `name`) as the server should get it: a
// string where it says more than its f64 (digits typed past f64's, or the
// point's own digits left as they were), else undefined for the number.
function asTyped(name, i, text) {
  if (!page.state.digit_points.includes(name)) return undefined;
  if (text === held(name, i)) return text;
  return significant(text) > 15 && String(parseFloat(text)) !== text ? text : undefined;
}

// Rodrigues' rotation of v about unit axis k.
function rotate(v, k, angle) {
  const c = Math.cos(angle), s = Math.sin(angle);
  return add(add(scale(v, c), scale(cross(k, v), s)), scale(k, dot(k, v) * (1 - c)));
}

// ---- points in digits -----------------------------------------------------------
// A deep camera is nearer its target than f64 tells apart: its moves take
// the offsets between points, exact in decimal (m × 10^e, m a BigInt), and
// add them to the points' digits, which the server keeps.

const MAX_DIGITS = 400;  // the digits a coordinate may have (exact::MAX_DIGITS)

function decimal(text) {
  const [mantissa, exponent = "0"] = text.replace(/^\+/, "").split(/[eE]/);
  const negative = mantissa.startsWith("-");
  const [whole, fraction = ""] = mantissa.replace(/^-/, "").split(".");
  const m = BigInt(whole + fraction || "0");
  return { m: negative ? -m : m, e: Number(exponent) - fraction.length };
}

// An f64 exactly: its significand times a power of two, 2^-k = 5^k × 10^-k.
function exactly(v) {
  const view = new DataView(new ArrayBuffer(8));
  view.setFloat64(0, v);
  const bits = view.getBigUint64(0);
  const biased = Number((bits >> 52n) & 0x7ffn);
  let m = bits & ((1n << 52n) - 1n);
  if (biased > 0) m |= 1n << 52n;
  const power = Math.max(biased, 1) - 1075;
  if (bits >> 63n) m = -m;
  return power >= 0 ? { m: m << BigInt(power), e: 0 } : { m: m * 5n ** BigInt(-power), e: power };
}

function plus(a, b) {
  const e = Math.min(a.e, b.e);
  return { m: a.m * 10n ** BigInt(a.e - e) + b.m * 10n ** BigInt(b.e - e), e };
}

const minus = (a, b) => plus(a, { m: -b.m, e: b.e });
const nearest = (d) => parseFloat(`${d.m}e${d.e}`);
// The shortest digits that read back as v: what an offset in f64 means.
const shortest = (v) => decimal(v.toExponential());

// Digits the server takes: plain, or one digit before the point and an
// exponent, rounded to MAX_DIGITS significant digits.
function written(d) {
  let digits = (d.m < 0n ? -d.m : d.m).toString(), e = d.e;
  const sign = d.m < 0n ? "-" : "";
  if (digits.length > MAX_DIGITS) {
    const cut = digits.length - MAX_DIGITS;
    const kept = (BigInt(digits) + 5n * 10n ** BigInt(cut - 1)) / 10n ** BigInt(cut);
    digits = kept.toString();
    e += cut + (digits.length - MAX_DIGITS);
    digits = digits.slice(0, MAX_DIGITS);
  }
  const zeros = digits.match(/0*$/)[0].length;
  if (zeros === digits.length) return "0";
  digits = digits.slice(0, digits.length - zeros);
  e += zeros;
  const point = digits.length + e;  // digits before the decimal point
  const plain = e >= 0 ? digits + "0".repeat(e)
    : point > 0 ? `${digits.slice(0, point)}.${digits.slice(point)}`
    : `0.${"0".repeat(-point)}${digits}`;
  if (plain.replace(".", "").length <= MAX_DIGITS) return sign + plain;
  return `${sign}${digits[0]}.${digits.slice(1) || "0"}e${point - 1}`;
}

// Point `name` in the view, exactly: its digits where it has them, else its numbers.
function exactPoint(name) {
  const numbers = value(name);
  const over = page.overrides[name];
  const typed = over ? page.typed[name] || [] : page.digits[name] || [];
  return numbers.map((v, i) => (typed[i] !== undefined ? decimal(typed[i]) : exactly(v)));
}

function heldInDigits(name) {
  return Boolean(page.overrides[name] ? page.typed[name] : page.digits[name]);
}

// Whether the camera, or its target, is held in digits and nearer the
// target than f64 positions keep apart (2^-30 of its size, as the server
// judges): its moves then take exactPoint.
function deepCamera() {
  if (!heldInDigits("camera.position") && !heldInDigits("camera.target")) return false;
  const away = offsetTo(exactPoint("camera.position"), exactPoint("camera.target"));
  const size = Math.max(...value("camera.target").map(Math.abs));
  return Math.max(...away.map(Math.abs)) < 2 ** -30 * size;
}

function changeExact(name, point) {
  change(name, point.map(nearest));
  page.typed[name] = point.map(written);
}

// `origin` + `offset` (f64 numbers) as exact digits.
const offsetFrom = (origin, offset) => origin.map((o, i) => plus(o, shortest(offset[i])));
const offsetTo = (point, origin) => point.map((p, i) => nearest(minus(p, origin[i])));

// The camera's offset from its target turned by a drag of (dx, dy) pixels.
function turned(away, dx, dy) {
  const up = norm(value("camera.up"));
  away = rotate(away, up, -dx * 0.008);
  const right = norm(cross(up, away));
  const tilted = rotate(away, right, -dy * 0.008);
  // Not over the pole, where the view would flip about the up direction;
  // a turn away from it is always taken.
  const pole = (v) => Math.abs(dot(norm(v), up));
  return pole(tilted) < 0.995 || pole(tilted) < pole(away) ? tilted : away;
}

function orbit(dx, dy) {
  if (!deepCamera()) {
    const target = value("camera.target");
    change("camera.position", add(target, turned(sub(value("camera.position"), target), dx, dy)));
    return;
  }
  const target = exactPoint("camera.target");
  const away = offsetTo(exactPoint("camera.position"), target);
  changeExact("camera.position", offsetFrom(target, turned(away, dx, dy)));
}

// Moves the camera and target towards `point` by `factor` (< 1 is closer):
// the point stays where it is in the frame. `exact` is the point's digits
// as decimals where a pick gave them. A point held in digits moves in them.
function zoomAbout(point, factor, exact) {
  // A zoom track places the camera at its distance: the zoom changes that.
  const distance = page.overrides["camera.distance"]
    || (trackNamed("camera.distance") && value("camera.distance"));
  if (distance) change("camera.distance", [distance[0] * factor]);
  const target = value("camera.target");
  const about = point === target ? exactPoint("camera.target") : exact || point.map(exactly);
  const closer = (name, inDigits) => {
    if (!inDigits) {
      change(name, add(point, scale(sub(value(name), point), factor)));
      return;
    }
    const away = offsetTo(exactPoint(name), about);
    changeExact(name, offsetFrom(about, scale(away, factor)));
  };
  closer("camera.position", deepCamera());
  if (point !== target) closer("camera.target", heldInDigits("camera.target"));
}

function roll(degrees) {
  change("camera.roll_degrees", [(value("camera.roll_degrees") || [0])[0] + degrees]);
}

// The view's pixel under a pointer event.
function pixelAt(event) {
  const img = $("view");
  const rect = img.getBoundingClientRect();
  const [w, h] = viewSize();
  // The image keeps its aspect inside the element (object-fit: contain).
  const k = Math.min(rect.width / w, rect.height / h);
  const x = (event.clientX - rect.left - (rect.width - w * k) / 2) / k;
  const y = (event.clientY - rect.top - (rect.height - h * k) / 2) / k;
  if (x < 0 || y < 0 || x >= w || y >= h) return null;
  return [Math.floor(x), Math.floor(y)];
}

function viewSize() {
  const size = $("size").value.trim().split(/[xX]/).map(Number);
  if (size.length === 2 && size[0] > 0 && size[1] > 0) return size;
  return [page.state.width, page.state.height];
}

async function aimAt(pixel) {
  try {
    const hit = await pickAt(pixel);
    if (!hit) { say("That pixel sees no surface."); return; }
    if (hit.exact) changeExact("camera.target", hit.exact);
    else change("camera.target", hit.point);
    say(`Aimed at (${hit.point.map((v) => v.toPrecision(8)).join(", ")}).`);
    refresh();
  } catch (error) { alertShown(error.message); }
}

// The surface point a pixel sees, with its digits (as decimals) in a deep frame.
async function pickAt(pixel) {
  const response = await api("/api/pick", { view: currentView(), x: pixel[0], y: pixel[1] });
  const report = await response.json();
  if (!report.point) return null;
  return { point: report.point, exact: report.point_digits && report.point_digits.map(decimal) };
}

// ---- pointer, wheel and keys -------------------------------------------------

function setUpViewport() {
  const viewport = $("viewport");
  let down = null;
  // The drag follows the pointer over the whole window, not just the image.
  viewport.addEventListener("pointerdown", (event) => {
    // A press of the pointer already down is not a new drag; another
    // pointer's press starts one (a lost release must not block drags).
    if (event.button !== 0 || (down && event.pointerId === down.id)) return;
    event.preventDefault();
    viewport.focus();
    down = { x: event.clientX, y: event.clientY, moved: false, id: event.pointerId };
  });
  window.addEventListener("pointermove", (event) => {
    if (!down || event.pointerId !== down.id) return;
    // Released outside the window: no pointerup came.
    if (event.buttons === 0) { release(event, false); return; }
    const dx = event.clientX - down.x, dy = event.clientY - down.y;
    if (!down.moved && Math.hypot(dx, dy) < 4) return;
    down.moved = true;
    page.dragging = true;
    viewport.classList.add("dragging");
    orbit(dx, dy);
    down.x = event.clientX;
    down.y = event.clientY;
    refreshSoon();
  });
  // A press that did not move is a click: aim at the surface point under it.
  const release = (event, clicked) => {
    if (down && event.pointerId !== down.id) return;
    const was = down;
    down = null;
    viewport.classList.remove("dragging");
    if (!was) return;
    if (was.moved) {
      page.dragging = false;
      if (!moving) refresh();
      return;
    }
    const pixel = clicked && pixelAt(event);
    if (pixel) aimAt(pixel);
  };
  window.addEventListener("pointerup", (event) => release(event, true));
  window.addEventListener("pointercancel", (event) => release(event, false));
  viewport.addEventListener("wheel", async (event) => {
    event.preventDefault();
    const factor = Math.exp(Math.max(-1, Math.min(1, event.deltaY * 0.0015)));
    const pixel = pixelAt(event);
    let hit = null;
    if (pixel) {
      const cached = page.pickCache;
      if (cached && cached.x === pixel[0] && cached.y === pixel[1] && performance.now() - cached.at < 400) {
        hit = cached.hit;
      } else {
        try {
          hit = await pickAt(pixel);
          page.pickCache = { x: pixel[0], y: pixel[1], hit, at: performance.now() };
        } catch (error) { alertShown(error.message); return; }
      }
      page.pickCache.at = performance.now();
    }
    if (hit) zoomAbout(hit.point, factor, hit.exact);
    else zoomAbout(value("camera.target"), factor);
    refreshSoon();
  }, { passive: false });
}

function setUpKeys() {
  document.addEventListener("keydown", (event) => {
    if ((event.ctrlKey || event.metaKey) && event.key.toLowerCase() === "s") {
      event.preventDefault();
      save(null);
      return;
    }
    const typing = ["INPUT", "TEXTAREA", "SELECT"].includes(document.activeElement.tagName);
    if (typing || event.ctrlKey || event.metaKey || event.altKey) return;
    const actions = {
      ArrowLeft: () => { orbit(-20, 0); refreshSoon(); },
      ArrowRight: () => { orbit(20, 0); refreshSoon(); },
      ArrowUp: () => { orbit(0, -20); refreshSoon(); },
      ArrowDown: () => { orbit(0, 20); refreshSoon(); },
      w: () => { zoomAbout(value("camera.target"), 0.8); refreshSoon(); },
      s: () => { zoomAbout(value("camera.target"), 1.25); refreshSoon(); },
      q: () => { roll(5); refreshSoon(); },
      e: () => { roll(-5); refreshSoon(); },
      ",": () => showFrame(page.frame - 1),
      ".": () => showFrame(page.frame + 1),
      " ": () => togglePlay(),
      k: () => keyChanges(),
      m: () => moveSelected(),
      Delete: () => deleteSelected(),
      Escape: () => discard(),
    };
    const action = actions[event.key];
    if (action && !(event.key === " " && document.activeElement.tagName === "BUTTON")) {
      event.preventDefault();
      action();
    }
  });
}

// ---- changes and keys ---------------------------------------------------------

function changedNames() { return Object.keys(page.overrides); }

function showChanges() {
  fillControls();
  const names = changedNames();
  $("changed").textContent = names.length
    ? "Changed: " + names.map((n) => `${n} = ${format(page.overrides[n])}`).join("; ")
    : "No changes at this frame.";
  for (const id of ["key", "set-scene", "discard"]) $(id).disabled = names.length === 0;
}

function format(numbers) {
  if (!numbers) return "off";
  const shown = numbers.map((v) => Number(v.toPrecision(6)));
  return shown.length === 1 ? String(shown[0]) : `(${shown.join(", ")})`;
}

// The changes as keys at this frame's time. A zoom track places the camera
// by its distance, so a moved camera keys that distance too.
function changeKeys() {
  const time = page.frame / page.state.fps;
  // A point is keyed as the view holds it: in its digits where it has them.
  const held = (name) => (page.overrides[name] ? sent(name) : page.digits[name] || value(name));
  const values = Object.fromEntries(changedNames().map((name) => [name, held(name)]));
  // A zoom track places the camera along the line from the target through
  // the position track's value: key all three as the view has them. The
  // line of a deep camera is keyed through a point a unit from the target,
  // which f64 tells apart from it.
  const moved = values["camera.position"] || values["camera.target"];
  if (trackNamed("camera.distance") && moved) {
    const away = offsetTo(exactPoint("camera.position"), exactPoint("camera.target"));
    values["camera.target"] = held("camera.target");
    values["camera.position"] = deepCamera() ? add(value("camera.target"), norm(away)) : held("camera.position");
    if (!values["camera.distance"]) values["camera.distance"] = [Math.hypot(...away)];
  }
  return Object.entries(values).map(([track, v]) => ({ kind: "set_key", track, time, value: v }));
}

// A first key on a parameter without a track would set it for the whole
// film: frame 0 keeps the value it has, keyed there.
async function startKeys(keys) {
  const first = keys.filter((k) => k.time > 0 && !trackNamed(k.track));
  if (!first.length) return [];
  const start = await (await api("/api/values?frame=0")).json();
  return first
    .filter((k) => start[k.track])
    .map((k) => ({ kind: "set_key", track: k.track, time: 0, value: start[k.track] }));
}

async function edit(edits, done, then = () => {}) {
  try {
    const state = await (await api("/api/edit", { edits })).json();
    alertShown("");
    say(done);
    page.overrides = {};
    page.typed = {};
    then();
    await loadState(state);
  } catch (error) {
    alertShown(error.message);
  }
}

async function keyChanges() {
  if (!changedNames().length) { say("Nothing changed to key."); return; }
  const keys = changeKeys();
  let starts;
  try { starts = await startKeys(keys); } catch (error) { alertShown(error.message); return; }
  const started = starts.map((e) => e.track);
  const start = started.length
    ? ` New track${started.length > 1 ? "s" : ""} ${started.join(", ")} also keyed at frame 0 with the value there, so frame 0 stays as it was and the value moves to the new one by frame ${page.frame}.`
    : "";
  edit(keys.concat(starts), `Keyed ${keys.map((e) => e.track).join(", ")} at frame ${page.frame}.${start}`);
}

// The zoom's distance is a track's alone, and a zoom track places the camera
// whatever the scene says: such changes are keyed, not set.
function setInScene() {
  const names = changedNames().filter((n) => n !== "camera.distance");
  const camera = names.some((n) => n.startsWith("camera.position") || n.startsWith("camera.target"));
  if (changedNames().includes("camera.distance")) {
    alertShown("camera.distance is a track's value, never the scene's: key it (K) instead.");
    return;
  }
  if (camera && trackNamed("camera.distance")) {
    alertShown("The camera.distance track places the camera whatever the scene says: key the camera (K) instead.");
    return;
  }
  if (!names.length) return;
  const edits = names.map((parameter) => ({ kind: "set_scene", parameter, value: sent(parameter) }));
  edit(edits, `Set ${names.join(", ")} in the scene.`);
}

function discard() {
  page.overrides = {};
  page.typed = {};
  fillControls();
  refresh();
}

function moveSelected() {
  const s = page.selected;
  if (!s) { say("Select a key first."); return; }
  const time = page.frame / page.state.fps;
  // The moved key stays selected, unless another was chosen meanwhile.
  const keep = () => { if (page.selected === s) page.selected = { ...s, time }; };
  edit([{ kind: "move_key", track: s.track, index: s.index, time }],
    `Moved the key of ${s.track} to frame ${page.frame}.`, keep);
}

function deleteSelected() {
  const s = page.selected;
  if (!s) { say("Select a key first."); return; }
  page.selected = null;
  edit([{ kind: "delete_key", track: s.track, index: s.index }], `Deleted a key of ${s.track}.`);
}

// ---- the strip of tracks ------------------------------------------------------------

function drawStrip() {
  const strip = $("strip");
  strip.textContent = "";
  const duration = Math.max(page.state.frames - 1, 1) / page.state.fps;
  const at = (time) => `${Math.max(0, Math.min(100, (time / duration) * 100))}%`;
  if (!page.state.tracks.length) {
    strip.textContent = "No tracks yet: change a value and press Key changes.";
    return;
  }
  for (const track of page.state.tracks) {
    const row = document.createElement("div");
    row.className = "track";
    const label = document.createElement("span");
    label.className = "label";
    label.textContent = `${track.name} (${track.interpolation})`;
    label.title = label.textContent;
    const lane = document.createElement("div");
    lane.className = "lane";
    const cursor = document.createElement("div");
    cursor.className = "cursor";
    cursor.style.left = at(page.frame / page.state.fps);
    lane.append(cursor);
    track.keys.forEach((key, index) => {
      const mark = document.createElement("button");
      mark.className = "keymark";
      const selected = page.selected && page.selected.track === track.name && page.selected.index === index;
      if (selected) mark.classList.add("selected");
      mark.style.left = at(key.time);
      const frame = Math.round(key.time * page.state.fps);
      mark.title = `${track.name}, key at frame ${frame} (${Number(key.time.toFixed(4))} s): ${format(key.value)}`;
      mark.setAttribute("aria-label", mark.title);
      mark.dataset.track = track.name;
      mark.dataset.index = index;
      mark.addEventListener("click", () => {
        page.selected = { track: track.name, index, time: key.time };
        $("selected").textContent = `Selected: ${mark.title}`;
        showFrame(Math.round(key.time * page.state.fps));
      });
      lane.append(mark);
    });
    row.append(label, lane);
    strip.append(row);
  }
}

// The selected key found again by its time, as the keys may have moved.
function reselected(selected) {
  const track = selected && trackNamed(selected.track);
  const index = track ? track.keys.findIndex((k) => Math.abs(k.time - selected.time) < 1e-9) : -1;
  if (index < 0) { $("selected").textContent = "No key selected."; return null; }
  return { ...selected, index };
}

// ---- the parameters -----------------------------------------------------------------

function buildControls() {
  const box = $("controls");
  for (const old of box.querySelectorAll(".group")) old.remove();
  const groups = new Map();
  for (const [name, components] of page.state.parameters) {
    const group = name.split(".")[0];
    if (!groups.has(group)) {
      const section = document.createElement("div");
      section.className = "group";
      const title = document.createElement("h2");
      title.textContent = group;
      section.append(title);
      groups.set(group, section);
      box.append(section);
    }
    const row = document.createElement("div");
    row.className = "param";
    row.dataset.name = name;
    const label = document.createElement("label");
    // A long name breaks after a dot, where it reads best.
    name.slice(group.length + 1).split(".").forEach((part, i) => {
      if (i > 0) label.append(".", document.createElement("wbr"));
      label.append(part);
    });
    label.title = name;
    row.append(label);
    for (let i = 0; i < components; i++) {
      const input = document.createElement("input");
      input.type = "number";
      input.step = "any";
      input.setAttribute("aria-label", components > 1 ? `${name} ${"xyz"[i]}` : name);
      input.addEventListener("change", () => changeFromControl(row, name));
      row.append(input);
    }
    groups.get(group).append(row);
  }
}

function fillControls() {
  for (const row of document.querySelectorAll(".param")) {
    const name = row.dataset.name;
    let numbers = page.overrides[name] || page.values[name];
    // A moved camera's distance is the one it now stands at.
    if (name === "camera.distance" && !page.overrides[name]) {
      numbers = [Math.hypot(...sub(value("camera.position"), value("camera.target")))];
    }
    row.classList.toggle("changed", name in page.overrides);
    // A fisheye's angle and stereo's separation only where the camera has them.
    row.hidden = !numbers && ["camera.projection.degrees", "camera.stereo.eye_separation"].includes(name);
    row.querySelectorAll("input").forEach((input, i) => {
      // Every digit the file holds (the shortest text that reads back as
      // the number, or the point's own strings of digits): a component
      // nobody touched goes back unchanged.
      const typed = (page.typed[name] || [])[i];
      const digits = page.overrides[name] ? undefined : held(name, i);
      input.value = typed ?? digits ?? (numbers ? String(numbers[i]) : "");
      input.title = input.value;
      input.placeholder = numbers ? "" : "off";
    });
  }
  showAutoIterations();
}

// `iterations: Auto` chooses each frame's count: shown, never edited here
// (the server refuses a number over `Auto`).
function showAutoIterations() {
  const row = document.querySelector('.param[data-name="fractal.iterations"]');
  const auto = page.iterations && page.iterations.decided;
  if (!row) return;
  let note = row.querySelector(".auto");
  if (auto && !note) {
    note = document.createElement("span");
    note.className = "auto";
    note.id = "auto-iterations";
    note.title = "iterations: Auto chooses each frame's count; write a number in the timeline's text to fix it";
    row.append(note);
  }
  if (note) note.hidden = !auto;
  if (note && auto) note.textContent = page.iterations.shown;
  row.querySelectorAll("input").forEach((input) => { input.hidden = Boolean(auto); });
}

function changeFromControl(row, name) {
  const texts = [...row.querySelectorAll("input")].map((input) => input.value.trim());
  const numbers = texts.map(parseFloat);
  if (numbers.some((v) => !Number.isFinite(v))) { say(`${name}: every field needs a number.`); return; }
  page.overrides[name] = numbers;
  // Digits past f64's go to the server as typed: a deep target keeps them.
  const typed = texts.map((t, i) => asTyped(name, i, t));
  if (typed.some((t) => t !== undefined)) page.typed[name] = typed;
  else delete page.typed[name];
  row.classList.add("changed");
  refresh();
}

// ---- playback -----------------------------------------------------------------------

// Plays from this frame until stopped, then shows the last frame played.
async function togglePlay() {
  if (page.playing) { page.playing = false; $("play").textContent = "Play"; return; }
  const run = page.playing = {};
  $("play").textContent = "Stop";
  const version = page.state;
  page.serial++;  // the view's stages in flight are dropped
  let frame = page.frame, shown = page.frame;
  while (page.playing === run && page.state === version) {
    const started = performance.now();
    const view = { ...currentView(false), frame };
    const cached = `${frame} ${view.size || ""} ${view.samples || ""}`;
    let url = page.playCache.get(cached);
    if (!url) {
      try {
        const response = await api("/api/render", { view, stage: "play" });
        url = URL.createObjectURL(await response.blob());
        page.playCache.set(cached, url);
      } catch (error) { alertShown(error.message); break; }
    }
    if (page.playing !== run) break;
    $("view").src = url;
    $("view").dataset.stage = "play";
    $("frame").value = $("slider").value = shown = frame;
    $("overlay").textContent = `playing frame ${frame}`;
    const wait = 1000 / page.state.fps - (performance.now() - started);
    if (wait > 0) await new Promise((r) => setTimeout(r, wait));
    frame = (frame + 1) % page.state.frames;
  }
  if (page.playing === run) page.playing = false;
  if (page.playing) return;  // a new run started meanwhile
  $("play").textContent = "Play";
  await showFrame(shown);
}

// ---- saving and the file -------------------------------------------------------------

async function save(name, overwrite = false) {
  if (!name && !page.state.path) {
    name = prompt("Save the new timeline as (name.ron, in the folder explore started in):");
    if (!name) return;
  }
  try {
    const body = name ? { name } : { overwrite };
    const state = await (await api("/api/save", body)).json();
    alertShown("");
    say(`Saved ${state.path}.`);
    await loadState(state);
  } catch (error) {
    if (error.status === 409 && confirm(`${error.message}\n\nWrite over the file on disk?`)) {
      return save(null, true);
    }
    alertShown(error.message);
  }
}

async function reload() {
  try {
    const state = await (await api("/api/reload", {})).json();
    alertShown("");
    say("Read the file again.");
    page.overrides = {};
    page.typed = {};
    await loadState(state);
  } catch (error) { alertShown(error.message); }
}

function listen() {
  const events = new EventSource(`/api/events?token=${TOKEN}`);
  events.onmessage = async (message) => {
    const event = JSON.parse(message.data);
    if (event.kind === "progress") {
      $("progress").value = event.of ? event.done / event.of : 0;
      $("progress").title = `${event.stage}: ${event.done} of ${event.of} rows`;
    } else if (event.kind === "file") {
      if (event.error) alertShown(`The file on disk has an error; the page keeps the last valid timeline.\n${event.error}`);
      else if (event.dirty) alertShown("The file changed on disk. Save writes over it; Reload takes it and drops the edits here.");
      else { alertShown(""); say("The file changed on disk: taken in."); await loadState(); }
    }
  };
}

// ---- start ------------------------------------------------------------------------

function setUp() {
  setUpViewport();
  setUpKeys();
  $("prev").onclick = () => showFrame(page.frame - 1);
  $("next").onclick = () => showFrame(page.frame + 1);
  $("play").onclick = togglePlay;
  $("frame").onchange = () => showFrame(parseInt($("frame").value, 10) || 0);
  $("slider").oninput = () => showFrame(parseInt($("slider").value, 10));
  $("key").onclick = keyChanges;
  $("set-scene").onclick = setInScene;
  $("discard").onclick = discard;
  $("move-key").onclick = moveSelected;
  $("delete-key").onclick = deleteSelected;
  $("save").onclick = () => save(null);
  $("save-as").onclick = () => {
    const name = prompt("Save as a new file in the same folder (name.ron):");
    if (name) save(name);
  };
  $("reload").onclick = reload;
  $("size").onchange = refresh;
  $("samples").onchange = refresh;
  $("help-button").onclick = () => {
    const help = $("help");
    help.hidden = !help.hidden;
    $("help-button").setAttribute("aria-expanded", String(!help.hidden));
  };
  $("estimate").onclick = async () => {
    $("estimate-result").textContent = "Measuring…";
    try {
      const e = await (await api("/api/estimate", currentView(false))).json();
      $("estimate-result").textContent =
        `About ${duration(e.seconds)} for all ${page.state.frames} frames on this machine ` +
        `(from ${e.frames_measured} frames rendered at ${e.measured_size.join("x")} with ` +
        `${e.measured_samples} sample(s), scaled by pixels and samples).`;
    } catch (error) { $("estimate-result").textContent = error.message; }
  };
  listen();
  // The estimate once the first view has had its turn.
  loadState()
    .then(() => setTimeout(() => $("estimate").click(), 2000))
    .catch((error) => alertShown(error.message));
}

function duration(seconds) {
  if (seconds < 90) return `${seconds.toFixed(1)} s`;
  if (seconds < 5400) return `${(seconds / 60).toFixed(1)} min`;
  return `${(seconds / 3600).toFixed(1)} h`;
}

setUp();

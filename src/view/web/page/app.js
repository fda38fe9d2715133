// The browser viewer's page: input capture and display only. Every decision (camera navigation, settings,
// when to render, statistics) is made by the server's session; this script turns DOM events into the
// messages of src/view/web/protocol.h and shows the frames and the state that come back.
'use strict';

const FRAME_MAGIC = 0x31465250;      // "PRF1"
const SCREENSHOT_MAGIC = 0x31535250; // "PRS1"
const HEADER_BYTES = 32;
const FLAG_FULL = 1;
// CloudCompare's view keys on the number row and the keypad, and the viewer's letters (pointrast view).
const KEYS = {
  KeyW: 'Forward', KeyS: 'Back', KeyA: 'Left', KeyD: 'Right', KeyQ: 'Down', KeyE: 'Up',
  KeyF: 'FrameAll', KeyK: 'Keyframe', KeyH: 'TogglePanel', KeyC: 'PrintCamera', F12: 'Screenshot',
  Digit8: 'ViewTop', Numpad8: 'ViewTop', Digit2: 'ViewBottom', Numpad2: 'ViewBottom',
  Digit5: 'ViewFront', Numpad5: 'ViewFront', Digit0: 'ViewBack', Numpad0: 'ViewBack',
  Digit4: 'ViewLeft', Numpad4: 'ViewLeft', Digit6: 'ViewRight', Numpad6: 'ViewRight',
  Digit1: 'ViewIso', Numpad1: 'ViewIso',
};
const FLY = new Set(['Forward', 'Back', 'Left', 'Right', 'Down', 'Up']);
// Two taps within this time and distance (CSS pixels) are a double-tap: the pivot, as a double-click.
const DOUBLE_TAP_MS = 350, DOUBLE_TAP_PX = 24;

const canvas = document.getElementById('view');
const ctx = canvas.getContext('2d');
const $ = (id) => document.getElementById(id);

// What tests and scripts read: the server's last info and state, and the frames drawn.
const pointrast = window.pointrast = {
  info: null, state: null, frames: 0, fullFrames: 0, lastFrame: null, lastPick: null, cameraText: null,
  errors: [], refusals: [], closed: null, sentSeq: 0, picked: null, picks: 0, measurements: [], exported: null,
  profile: null, profileCuts: 0, profileDownload: null, profileImage: null,
};

let socket = null;
let seq = 0;
let drawing = Promise.resolve();
let pendingMove = null, pendingWheel = null, flushScheduled = false;
const heldKeys = new Set();

function send(message) {
  if (!socket || socket.readyState !== WebSocket.OPEN) return;
  if (message.t !== 'ack' && message.t !== 'resize') message.seq = pointrast.sentSeq = ++seq;
  socket.send(JSON.stringify(message));
}

// --- connection -----------------------------------------------------------------------------------------

function connect() {
  const page = new URL(location.href);
  const url = new URL('ws', page);
  url.protocol = page.protocol === 'https:' ? 'wss:' : 'ws:';
  url.search = '';
  const token = page.searchParams.get('token');
  if (token) {
    url.searchParams.set('token', token);
    // The server set a cookie with it: keep the token out of the address bar and the history.
    page.searchParams.delete('token');
    history.replaceState(null, '', page.pathname + page.search + page.hash);
  }
  socket = new WebSocket(url);
  socket.binaryType = 'arraybuffer';
  socket.onopen = () => { status(''); sendSize(true); };
  socket.onmessage = (event) => {
    if (typeof event.data === 'string') receiveText(JSON.parse(event.data));
    else receiveBinary(event.data);
  };
  socket.onclose = (event) => {
    pointrast.closed = { code: event.code, reason: event.reason };
    const why = event.reason || (pointrast.errors.length ? pointrast.errors[pointrast.errors.length - 1] : '');
    status('disconnected' + (why ? ': ' + why : '') + ' (reload to reconnect)', true);
  };
}

function status(text, error) {
  $('status').textContent = text;
  $('status').className = error ? 'error' : '';
}

// --- frames ---------------------------------------------------------------------------------------------

function receiveBinary(buffer) {
  const view = new DataView(buffer);
  const header = {
    magic: view.getUint32(0, true), frame: view.getUint32(4, true), seq: view.getUint32(8, true),
    width: view.getUint16(12, true), height: view.getUint16(14, true),
    viewWidth: view.getUint16(16, true), viewHeight: view.getUint16(18, true),
    quality: view.getUint8(20), full: (view.getUint8(21) & FLAG_FULL) !== 0,
    renderMs: view.getFloat32(24, true), encodeMs: view.getFloat32(28, true),
  };
  const payload = new Uint8Array(buffer, HEADER_BYTES);
  if (header.magic === SCREENSHOT_MAGIC) {
    download(new Blob([payload], { type: 'image/png' }), 'pointrast-screenshot.png');
    return;
  }
  if (header.magic !== FRAME_MAGIC) return;
  // Frames are drawn in order, one decode at a time; the server sends at most two ahead of the acks.
  drawing = drawing.then(() => drawFrame(header, payload));
}

async function drawFrame(header, jpeg) {
  try {
    const image = await createImageBitmap(new Blob([jpeg], { type: 'image/jpeg' }),
                                          { colorSpaceConversion: 'none', premultiplyAlpha: 'none' });
    // The canvas holds the server's viewport 1:1; a motion frame (smaller) is scaled up into it.
    if (canvas.width !== header.viewWidth || canvas.height !== header.viewHeight) {
      canvas.width = header.viewWidth;
      canvas.height = header.viewHeight;
    }
    ctx.imageSmoothingEnabled = true;
    ctx.drawImage(image, 0, 0, canvas.width, canvas.height);
    image.close();
    pointrast.frames++;
    if (header.full) pointrast.fullFrames++;
    pointrast.lastFrame = header;
    showStream(header, jpeg.byteLength);
  } catch (error) {
    pointrast.errors.push('frame ' + header.frame + ': ' + error);
  }
  send({ t: 'ack', frame: header.frame });
}

function download(blob, name) {
  const a = document.createElement('a');
  a.href = URL.createObjectURL(blob);
  a.download = name;
  a.click();
  setTimeout(() => URL.revokeObjectURL(a.href), 10000);
}

// --- state from the server ------------------------------------------------------------------------------

function receiveText(message) {
  switch (message.t) {
    case 'info': pointrast.info = message; buildPanel(message); break;
    case 'state': pointrast.state = message; showState(message); defaultProfileWidth(message); break;
    case 'pick': pointrast.lastPick = message; break;
    case 'picked': pointrast.picked = message.pick; pointrast.picks++; showPicked(message.pick); profilePicked(message.pick); break;
    case 'moved': pointrast.moved = message.moved; pointrast.moves = (pointrast.moves || 0) + 1; if (message.moved.pick) showPicked(message.moved.pick); break;
    case 'measurements': pointrast.measurements = message.list; pointrast.measurementUpdates = (pointrast.measurementUpdates || 0) + 1; showMeasurements(message.list); break;
    case 'annotations': download(new Blob([message.text], { type: 'application/json' }), 'annotations.json'); break;
    case 'camera': pointrast.cameraText = message.text; $('cameraText').textContent = 'pointrast render FILE ' + message.text; break;
    case 'refused': pointrast.refusals.push(message.text); status(message.text, true); break;
    case 'path': download(new Blob([JSON.stringify(message.path, null, 1)], { type: 'application/json' }), 'path.json'); break;
    case 'error': pointrast.errors.push(message.message); status(message.message, true); break;
  }
}

function human(n) {
  const units = [[1e12, 'T'], [1e9, 'G'], [1e6, 'M'], [1e3, 'k']];
  for (const [v, u] of units) if (n >= v) return (n / v).toFixed(n / v >= 100 ? 0 : 1) + ' ' + u;
  return String(Math.round(n));
}

const fmt = (v, d) => Number(v).toFixed(d);
const vec = (v) => v.map((x) => fmt(x, 3)).join(', ');

function buildPanel(info) {
  const select = $('method');
  select.textContent = '';
  for (const m of info.methods) {
    const option = document.createElement('option');
    option.value = option.textContent = m.name;
    option.title = m.help;
    select.appendChild(option);
  }
  $('panel').hidden = false;
}

// What the stream delivers, measured here from the frames drawn: the server's state message goes before
// its frame, so its figures would always lag one frame behind.
const stream = { drawn: [], motionBytes: [], fullBytes: 0 };

function showStream(header, bytes) {
  const now = performance.now();
  stream.drawn.push(now);
  while (stream.drawn.length && now - stream.drawn[0] > 1000) stream.drawn.shift();
  if (header.full) {
    stream.fullBytes = bytes;
  } else {
    stream.motionBytes.push(bytes);
    if (stream.motionBytes.length > 60) stream.motionBytes.shift();
  }
  const motion = stream.motionBytes.length ? stream.motionBytes.reduce((a, b) => a + b, 0) / stream.motionBytes.length : 0;
  $('streamStats').textContent = [
    `JPEG encode ${fmt(header.encodeMs, 3).padStart(8)} ms  (sender thread)`,
    `stream ${header.width}x${header.height} q${header.quality}, ${stream.drawn.length} frames/s`,
    `JPEG ${fmt(motion / 1024, 0)} KiB moving, ${fmt(stream.fullBytes / 1024, 0)} KiB at rest`,
  ].join('\n');
}

function showState(s) {
  const info = pointrast.info || { device: '', input: '', points: 0 };
  const st = s.stats;
  $('panel').hidden = !s.options.panel;
  if (s.settings.clipBox && !pointrast.clipShown) {
    $('clipBox').value = s.settings.clipBox.join(',');
    $('clipMode').value = s.settings.clipMode;
    pointrast.clipShown = true;
  }
  if (document.activeElement !== $('method')) $('method').value = s.settings.method;
  const bg = s.settings.background.join(',');
  let preset = false;
  for (const r of document.querySelectorAll('input[name=background]')) { r.checked = r.value === bg; preset ||= r.checked; }
  $('backgroundCustom').value = '#' + s.settings.background.map((c) => c.toString(16).padStart(2, '0')).join('');
  const lines = [
    info.device,
    `${info.input}: ${human(info.points)} points`,
    `GPU render  ${fmt(st.renderMs, 3).padStart(8)} ms  (clear + draw + resolve)`,
    `frame (host) ${fmt(st.hostMs, 2).padStart(7)} ms, ${st.frames} frames`,
    `points drawn ${human(st.points)}, ${human(st.pointsPerSecond)} points/s`,
  ];
  if (st.post) lines.push(`  resolve stage: splat ${fmt(st.post.splatMs, 3)}, dilate ${fmt(st.post.dilateMs, 3)}, compose ${fmt(st.post.composeMs, 3)} ms`);
  if (st.batch && !st.lod) lines.push(`batches ${human(st.batch.batchesRendered)} of ${human(st.batch.batchesProcessed)} rendered, ${human(st.batch.pointsRendered)} points passed early-z`);
  const lod = st.lod;
  if (lod) {
    lines.push(`nodes drawn ${human(lod.nodesDrawn)} of ${human(lod.nodesSelected)} selected (${human(lod.pointsDrawn)} points)${lod.budgetReached ? ', budget reached' : ''}`);
    lines.push(`nodes loaded ${human(lod.nodesLoaded)}, evicted ${human(lod.nodesEvicted)}, ${lod.passes} passes`);
    lines.push(`streamed ${fmt(lod.bytesPerSecond / 1e6, 1)} MB/s, ${fmt(lod.bytesStreamed / 1048576, 1)} MiB in all`);
    lines.push(`node cache ${fmt(lod.residentBytes / 1048576, 1)} of ${fmt(lod.cacheBytes / 1048576, 1)} MiB`);
  }
  lines.push(`GPU memory ${fmt(st.gpuBytes / 1048576, 1)} MiB (scene + targets)`);
  $('stats').textContent = lines.join('\n');
  const lodStatus = $('lodStatus');
  lodStatus.textContent = '';
  if (lod) {
    const state = document.createElement('span');
    state.className = lod.converged ? 'converged' : 'refining';
    state.textContent = lod.converged ? 'converged' : 'refining';
    lodStatus.appendChild(state);
  }
  if (st.status) lodStatus.appendChild(document.createTextNode((lod ? '  ' : '') + st.status));
  showSettings(s.settings);
  $('camera').textContent = `eye    ${vec(s.camera.eye)}\ntarget ${vec(s.camera.target)}\npivot  ${vec(s.pivot)}`;
  $('keyframes').textContent = `${s.keyframes.count} keyframes, ${fmt(s.keyframes.duration, 1)} s`;
  if (document.activeElement !== $('keyframeSeconds')) $('keyframeSeconds').value = s.options.keyframeSeconds;
  for (const r of document.querySelectorAll('input[name=supersample]')) r.checked = Number(r.value) === s.options.supersample;
  if (document.activeElement !== $('motionScale')) $('motionScale').value = String(s.stream.motionScale);
  if (document.activeElement !== $('quality')) $('quality').value = s.stream.quality;
  if (document.activeElement !== $('motionQuality')) $('motionQuality').value = s.stream.motionQuality;
}

// The controls show the server's settings, except the one being edited.
function show(id, value, property = 'value') {
  const element = $(id);
  if (document.activeElement !== element) element[property] = value;
}

function showSettings(v) {
  for (const r of document.querySelectorAll('input[name=depth]')) { r.checked = r.value === v.depth; r.disabled = !v.takesInt40; }
  show('color', v.color);
  const ramp = v.color === 'intensity' || v.color === 'elevation';
  $('colorRangeRow').hidden = !ramp;
  show('colorRange', v.colorRange !== null, 'checked');
  $('colorLo').disabled = $('colorHi').disabled = v.colorRange === null;
  if (v.colorRange !== null) { show('colorLo', v.colorRange[0]); show('colorHi', v.colorRange[1]); }
  $('post').disabled = !v.takesPost;
  $('postNote').textContent = v.takesPost ? '' : `${v.method} keeps no depth per pixel: no point size, dilation or EDL`;
  show('pointSize', v.pointSize);
  $('pointSizeText').textContent = `${v.pointSize} px`;
  for (const r of document.querySelectorAll('input[name=pointShape]')) r.checked = r.value === v.pointShape;
  show('attenuated', v.pointSizeMode === 'attenuated', 'checked');
  $('pointSizeMaxRow').hidden = v.pointSizeMode !== 'attenuated';
  show('pointSizeMax', v.pointSizeMax);
  show('dilate', v.dilate);
  $('dilateText').textContent = v.dilate ? `${v.dilate} px` : 'off';
  show('edl', v.edlStrength > 0, 'checked');
  $('edlRow').hidden = !(v.edlStrength > 0);
  if (v.edlStrength > 0) show('edlStrength', Number(v.edlStrength.toFixed(2)));
  show('edlRadius', Number(v.edlRadius.toFixed(2)));
  $('lod').disabled = !v.octree;
  show('minNodePx', v.minNodePx);
  show('pointBudget', v.pointBudget);
  show('gpuMemory', Math.round(v.gpuMemory / 1048576));
  $('stereoControls').disabled = !v.takesStereo;
  show('stereo', v.stereo, 'checked');
  show('crossed', v.crossed, 'checked');
  show('ipd', v.ipd);
  $('foveaControls').disabled = !v.takesFoveation;
  show('foveated', v.foveated, 'checked');
  $('foveaRadius').disabled = $('foveaPeriphery').disabled = !v.foveated;
  show('foveaRadius', v.foveaRadius);
  show('foveaPeriphery', v.foveaPeriphery);
}

// --- panel controls -------------------------------------------------------------------------------------

// A number typed into a field, sent when it is within [lo, hi]; anything else puts the server's value back.
function numberControl(id, lo, hi, message) {
  $(id).addEventListener('change', (e) => {
    const v = Number(e.target.value);
    if (e.target.value !== '' && v >= lo && v <= hi) send({ t: 'settings', ...message(v) });
    else if (pointrast.state) showSettings(pointrast.state.settings);
  });
}

for (const r of document.querySelectorAll('input[name=depth]'))
  r.addEventListener('change', () => send({ t: 'settings', depth: r.value }));
$('color').addEventListener('change', (e) => send({ t: 'settings', color: e.target.value }));
$('colorRange').addEventListener('change', (e) => {
  if (!e.target.checked) return send({ t: 'settings', colorRange: null });
  // Start from the ramp's usual ends: the cloud's heights, or the 16-bit intensity scale.
  const b = pointrast.state && pointrast.state.bounds;
  const range = $('color').value === 'elevation' && b ? [b.min[2], b.max[2]] : [0, 65535];
  send({ t: 'settings', colorRange: range });
});
for (const id of ['colorLo', 'colorHi'])
  $(id).addEventListener('change', () => {
    const lo = Number($('colorLo').value), hi = Number($('colorHi').value);
    if (Number.isFinite(lo) && Number.isFinite(hi) && lo < hi) send({ t: 'settings', colorRange: [lo, hi] });
    else if (pointrast.state) showSettings(pointrast.state.settings);
  });
numberControl('pointSize', 1, 32, (v) => ({ pointSize: v }));
for (const r of document.querySelectorAll('input[name=pointShape]'))
  r.addEventListener('change', () => send({ t: 'settings', pointShape: r.value }));
$('attenuated').addEventListener('change', (e) => send({ t: 'settings', pointSizeMode: e.target.checked ? 'attenuated' : 'fixed' }));
numberControl('pointSizeMax', 1, 32, (v) => ({ pointSizeMax: v }));
numberControl('dilate', 0, 8, (v) => ({ dilate: Math.round(v) }));
$('edl').addEventListener('change', (e) => send({ t: 'settings', edlStrength: e.target.checked ? 1 : 0 }));
numberControl('edlStrength', 0.05, 10, (v) => ({ edlStrength: v }));
numberControl('edlRadius', 0.5, 16, (v) => ({ edlRadius: v }));
numberControl('minNodePx', 0, 10000, (v) => ({ minNodePx: v }));
numberControl('pointBudget', 0, 2 ** 40, (v) => ({ pointBudget: Math.round(v) }));
numberControl('gpuMemory', 0, 2 ** 24, (v) => ({ gpuMemory: Math.round(v) * 1048576 }));
for (const id of ['stereo', 'crossed', 'foveated'])
  $(id).addEventListener('change', (e) => send({ t: 'settings', [id]: e.target.checked }));
numberControl('ipd', 0, 1e12, (v) => ({ ipd: v }));
numberControl('foveaRadius', 0, 1, (v) => ({ foveaRadius: v }));
numberControl('foveaPeriphery', 1, 100, (v) => ({ foveaPeriphery: v }));

$('method').addEventListener('change', (e) => send({ t: 'settings', method: e.target.value }));
for (const r of document.querySelectorAll('input[name=background]'))
  r.addEventListener('change', () => send({ t: 'settings', background: r.value.split(',').map(Number) }));
$('backgroundCustom').addEventListener('input', (e) => {
  const hex = e.target.value;
  send({ t: 'settings', background: [1, 3, 5].map((i) => parseInt(hex.slice(i, i + 2), 16)) });
});
for (const b of document.querySelectorAll('button[data-key]'))
  b.addEventListener('click', () => { send({ t: 'key', key: b.dataset.key, down: true }); canvas.focus(); });
$('clearKeyframes').addEventListener('click', () => send({ t: 'action', name: 'clearKeyframes' }));
$('downloadPath').addEventListener('click', () => send({ t: 'action', name: 'downloadPath' }));
$('keyframeSeconds').addEventListener('change', (e) => {
  const v = Number(e.target.value);
  if (v >= 0.1 && v <= 60) send({ t: 'options', keyframeSeconds: v });
});
for (const r of document.querySelectorAll('input[name=supersample]'))
  r.addEventListener('change', () => send({ t: 'options', supersample: Number(r.value) }));
$('motionScale').addEventListener('change', (e) => send({ t: 'stream', motionScale: Number(e.target.value) }));
$('quality').addEventListener('change', (e) => send({ t: 'stream', quality: Number(e.target.value) }));
$('motionQuality').addEventListener('change', (e) => send({ t: 'stream', motionQuality: Number(e.target.value) }));

// --- canvas size ----------------------------------------------------------------------------------------

let sentSize = '';
function sendSize(force) {
  const r = canvas.getBoundingClientRect();
  const w = Math.max(1, Math.round(r.width * devicePixelRatio));
  const h = Math.max(1, Math.round(r.height * devicePixelRatio));
  if (!force && `${w}x${h}` === sentSize) return;
  sentSize = `${w}x${h}`;
  send({ t: 'resize', w, h });
}
new ResizeObserver(() => requestAnimationFrame(() => sendSize(false))).observe(canvas);

// --- pointer, wheel, touch ------------------------------------------------------------------------------

// Positions go to the server normalized to the canvas (0..1): it scales them to its viewport.
function position(e) {
  const r = canvas.getBoundingClientRect();
  return { x: (e.clientX - r.left) / r.width, y: (e.clientY - r.top) / r.height };
}

// Moves and wheel steps are sent at most once per displayed frame of the page, the last position and the
// sum of the steps.
function scheduleFlush() {
  if (flushScheduled) return;
  flushScheduled = true;
  requestAnimationFrame(flush);
}

function flush() {
  flushScheduled = false;
  if (pendingMove) { send({ t: 'move', ...pendingMove }); pendingMove = null; }
  if (pendingWheel) {
    const steps = Math.max(-50, Math.min(50, pendingWheel.steps));
    if (steps !== 0) send({ t: 'wheel', x: pendingWheel.x, y: pendingWheel.y, steps });
    pendingWheel = null;
  }
}

function clampPosition(p) {
  return { x: Math.max(-4, Math.min(5, p.x)), y: Math.max(-4, Math.min(5, p.y)) };
}

const touches = new Map();
let touchMode = null, pinchDistance = 0, lastTap = null;

function midpoint() {
  const [a, b] = [...touches.values()];
  return { x: (a.x + b.x) / 2, y: (a.y + b.y) / 2 };
}

function spread() {
  const [a, b] = [...touches.values()];
  return Math.hypot(a.cx - b.cx, a.cy - b.cy);
}

function wheelAt(p, steps) {
  if (!pendingWheel) pendingWheel = { x: p.x, y: p.y, steps: 0 };
  pendingWheel.x = p.x;
  pendingWheel.y = p.y;
  pendingWheel.steps += steps;
  scheduleFlush();
}

function touchDown(e) {
  const p = clampPosition(position(e));
  touches.set(e.pointerId, { ...p, cx: e.clientX, cy: e.clientY });
  if (touches.size === 1) {
    const now = performance.now();
    if (lastTap && now - lastTap.time < DOUBLE_TAP_MS && Math.hypot(e.clientX - lastTap.cx, e.clientY - lastTap.cy) < DOUBLE_TAP_PX) {
      send({ t: 'dblclick', ...p });
      lastTap = null;
      touchMode = null;
      return;
    }
    lastTap = { time: now, cx: e.clientX, cy: e.clientY };
    send({ t: 'down', b: 0, ...p });
    touchMode = 'orbit';
  } else if (touches.size === 2) {
    flush();
    if (touchMode === 'orbit') send({ t: 'up', b: 0, ...p });
    send({ t: 'down', b: 2, ...midpoint() });
    touchMode = 'pan';
    pinchDistance = spread();
  }
}

function touchMove(e) {
  if (!touches.has(e.pointerId)) return;
  const p = clampPosition(position(e));
  touches.set(e.pointerId, { ...p, cx: e.clientX, cy: e.clientY });
  if (touchMode === 'orbit') {
    pendingMove = p;
    scheduleFlush();
  } else if (touchMode === 'pan' && touches.size === 2) {
    const m = midpoint();
    pendingMove = m;
    const d = spread();
    // Pinching apart by the wheel's zoom factor per step is one step in.
    if (pinchDistance > 0 && d > 0) wheelAt(m, Math.log(d / pinchDistance) / Math.log(1 / pointrast.info.zoomPerStep));
    pinchDistance = d;
    scheduleFlush();
  }
}

function touchUp(e) {
  if (!touches.has(e.pointerId)) return;
  const p = clampPosition(position(e));
  flush();
  if (touchMode === 'pan' && touches.size === 2) { send({ t: 'up', b: 2, ...midpoint() }); touchMode = null; }
  touches.delete(e.pointerId);
  if (touchMode === 'orbit' && touches.size === 0) { send({ t: 'up', b: 0, ...p }); touchMode = null; }
}

// --- tools: pick and measure -----------------------------------------------------------------------------

// A left click with a tool chosen (or Ctrl+click in any) picks the point under it; measuring tools add it
// as the next vertex of the open measurement. Pressed on a measurement's vertex and released elsewhere, the
// vertex moves to the point under the release. The press is kept until its release decides which.
let toolPress = null;
function toolClick(e) {
  const tool = $('tool').value;
  if (e.button !== 0 || (tool === 'navigate' && !e.ctrlKey)) return false;
  flush();
  toolPress = { at: clampPosition(position(e)), clientX: e.clientX, clientY: e.clientY, tool };
  return true;
}

function toolRelease(e) {
  if (!toolPress || e.button !== 0) return false;
  const press = toolPress;
  toolPress = null;
  if (Math.hypot(e.clientX - press.clientX, e.clientY - press.clientY) > 4) {
    const to = clampPosition(position(e));
    send({ t: 'measure', op: 'move', x: press.at.x, y: press.at.y, tx: to.x, ty: to.y });
    return true;
  }
  const message = { t: 'pickpoint', ...press.at };
  if (press.tool === 'distance' || press.tool === 'height' || press.tool === 'area') message.measure = press.tool;
  send(message);
  profilePicks.push(press.tool === 'profile');
  return true;
}

function showPicked(pick) {
  const p = pick.point;
  if (typeof p !== 'object') { $('picked').textContent = 'pixel ' + pick.pixel.join(',') + ': ' + p; return; }
  const lines = [`x ${p.x}`, `y ${p.y}`, `z ${p.z}`];
  for (const [name, label] of [['intensity', 'intensity'], ['classification', 'class'], ['return_number', 'return'],
                               ['number_of_returns', 'returns'], ['gps_time', 'GPS time'], ['point_source_id', 'source id'],
                               ['scan_angle', 'scan angle'], ['user_data', 'user data'], ['nir', 'NIR'],
                               ['classification_flags', 'class flags'], ['scanner_channel', 'channel'],
                               ['scan_direction_flag', 'scan direction'], ['edge_of_flight_line', 'edge of flight line']])
    if (name in p) lines.push(`${label} ${p[name]}`);
  if (p.color) lines.push('color ' + p.color.join(', '));
  // An octree's extra bytes fields, by their own names.
  for (const [name, value] of Object.entries(p.extra_bytes || {}))
    lines.push(`${name} ${Array.isArray(value) ? value.join(', ') : value}`);
  if (p.node) lines.push(`node ${p.node}`);
  $('picked').textContent = lines.join('\n');
}

function showMeasurements(list) {
  const box = $('measurements');
  box.replaceChildren();
  for (const m of list) {
    const row = document.createElement('div');
    row.className = 'measurement';
    const text = m.value !== undefined
      ? `${m.type} ${m.text}` + (m.segments.length > 1 ? ' (' + m.segments.map((d) => d.toFixed(2)).join(' + ') + ')' : '')
      : `${m.type}: ${m.points.length} point(s)` + (m.open ? ', click to add' : '');
    row.append(text + ' ');
    const remove = document.createElement('button');
    remove.className = 'small';
    remove.textContent = 'delete';
    remove.addEventListener('click', () => send({ t: 'measure', op: 'delete', index: m.index }));
    row.append(remove);
    box.append(row);
  }
}

$('finishMeasure').addEventListener('click', () => send({ t: 'measure', op: 'finish' }));
$('clearMeasures').addEventListener('click', () => send({ t: 'measure', op: 'clear' }));
$('downloadMeasures').addEventListener('click', () => send({ t: 'measure', op: 'download' }));
$('tool').addEventListener('change', () => send({ t: 'measure', op: 'finish' }));

// --- clip box and export ----------------------------------------------------------------------------------

function clipBoxValue() {
  const text = $('clipBox').value.trim();
  if (!text) return null;
  const v = text.split(',').map(Number);
  return v.length === 6 && v.every(Number.isFinite) ? v : undefined;
}

$('applyClip').addEventListener('click', () => {
  const box = clipBoxValue();
  if (box === undefined) { status('the clip box takes six numbers: x0,y0,z0,x1,y1,z1', true); return; }
  send({ t: 'settings', clipBox: box, clipMode: $('clipMode').value });
});

// The export is an HTTP request of its own (the access cookie goes along): the points inside the box in the
// fields (or outside it), of the classes listed, as the LAS file convert would write.
$('exportLas').addEventListener('click', async () => {
  const box = clipBoxValue();
  if (box === undefined) { status('the clip box takes six numbers: x0,y0,z0,x1,y1,z1', true); return; }
  const query = new URLSearchParams();
  if (box) { query.set('box', box.join(',')); query.set('mode', $('clipMode').value); }
  const classes = $('exportClasses').value.replace(/\s/g, '');
  if (classes) query.set('classes', classes);
  $('exportStatus').textContent = 'exporting...';
  try {
    const response = await fetch('export.las?' + query.toString());
    if (!response.ok) {
      const why = (await response.text()).trim();
      pointrast.exported = { error: why };
      $('exportStatus').textContent = why;
      status(why, true);
      return;
    }
    const points = Number(response.headers.get('X-Points'));
    download(await response.blob(), 'export.las');
    pointrast.exported = { points };
    $('exportStatus').textContent = `${points} points exported`;
  } catch (error) {
    pointrast.exported = { error: String(error) };
    $('exportStatus').textContent = String(error);
  }
});

// --- profile -----------------------------------------------------------------------------------------------

// The profile tool's clicks pick points (answered in order, one 'picked' each): their x/y become the next
// vertices of the line. The picture and the downloads are HTTP requests of their own, cut by the server
// with `pointrast profile`'s code: the picture equals `pointrast profile FILE --line L --width W --size S -o`.
const profilePicks = [];
let profileRequest = 0;

function profilePicked(pick) {
  if (!profilePicks.length || !profilePicks.shift()) return;
  const p = pick.point;
  if (typeof p !== 'object') {
    pointrast.profile = { error: 'no point under the click: ' + p };
    pointrast.profileCuts++;
    $('profileStatus').textContent = pointrast.profile.error;
    return;
  }
  const line = $('profileLine').value.replace(/\s/g, '');
  $('profileLine').value = (line ? line + ',' : '') + String(p.x) + ',' + String(p.y);
  if (profileLineValue().length >= 4) cutProfile();
  else $('profileStatus').textContent = 'click the next vertex';
}

// A width for the data: a hundredth of the cloud's larger horizontal side, two significant digits.
function defaultProfileWidth(state) {
  if ($('profileWidth').value !== '' || !state.bounds) return;
  const side = Math.max(state.bounds.max[0] - state.bounds.min[0], state.bounds.max[1] - state.bounds.min[1]);
  if (side > 0) $('profileWidth').value = String(Number((side / 100).toPrecision(2)));
}

function profileLineValue() {
  const text = $('profileLine').value.replace(/\s/g, '');
  return text ? text.split(',') : [];
}

// The query of a profile request, or a sentence saying what is missing.
function profileQuery(picture) {
  const line = profileLineValue();
  if (line.length < 4 || line.length % 2 !== 0 || !line.every((v) => v !== '' && Number.isFinite(Number(v))))
    return 'the profile needs a line of two or more x,y vertices: click them with the profile tool';
  const width = $('profileWidth').value.trim();
  if (!(Number(width) > 0)) return 'the profile needs a positive width';
  const query = new URLSearchParams({ line: line.join(','), width });
  if (picture) query.set('size', $('profileSize').value.trim());
  return query;
}

async function profileFetch(file, query) {
  const response = await fetch(file + '?' + query.toString());
  if (!response.ok) throw new Error((await response.text()).trim());
  return { blob: await response.blob(), points: Number(response.headers.get('X-Points')) };
}

async function cutProfile() {
  const query = profileQuery(true);
  if (typeof query === 'string') {
    pointrast.profile = { error: query };
    pointrast.profileCuts++;
    $('profileStatus').textContent = query;
    return;
  }
  const request = ++profileRequest;
  $('profileStatus').textContent = 'cutting...';
  try {
    const { blob, points } = await profileFetch('profile.png', query);
    if (request !== profileRequest) return; // a newer cut is on its way
    const image = $('profileImage');
    if (image.src) URL.revokeObjectURL(image.src);
    image.src = URL.createObjectURL(blob);
    pointrast.profileImage = blob; // the PNG's bytes as the server sent them
    await image.decode();
    $('profilePanel').hidden = false;
    const width = query.get('width');
    $('profileCaption').textContent = `${points} points within ${Number(width) / 2} of the line`;
    $('profileStatus').textContent = `${points} points`;
    pointrast.profile = { line: query.get('line'), width, size: query.get('size'), points };
    pointrast.profileCuts++;
  } catch (error) {
    if (request !== profileRequest) return;
    const why = error.message || String(error);
    pointrast.profile = { error: why };
    pointrast.profileCuts++;
    $('profileStatus').textContent = why;
    status(why, true);
  }
}

async function downloadProfile(kind) {
  const query = profileQuery(false);
  if (typeof query === 'string') { $('profileStatus').textContent = query; return; }
  $('profileStatus').textContent = 'cutting...';
  try {
    const { blob, points } = await profileFetch('profile.' + kind, query);
    download(blob, 'profile.' + kind);
    pointrast.profileDownload = { kind, points, line: query.get('line'), width: query.get('width') };
    $('profileStatus').textContent = `${points} points in profile.${kind}`;
  } catch (error) {
    const why = error.message || String(error);
    pointrast.profileDownload = { kind, error: why };
    $('profileStatus').textContent = why;
    status(why, true);
  }
}

$('profileCut').addEventListener('click', cutProfile);
$('profileLas').addEventListener('click', () => downloadProfile('las'));
$('profileCsv').addEventListener('click', () => downloadProfile('csv'));
$('profileClear').addEventListener('click', () => {
  $('profileLine').value = '';
  $('profileStatus').textContent = '';
  $('profilePanel').hidden = true;
  profileRequest++;
});
$('profileClose').addEventListener('click', () => { $('profilePanel').hidden = true; });

let buttonsDown = 0;
canvas.addEventListener('pointerdown', (e) => {
  canvas.focus();
  canvas.setPointerCapture(e.pointerId);
  if (e.pointerType === 'touch') return touchDown(e);
  if (e.button > 2) return;
  if (toolClick(e)) return;
  flush();
  buttonsDown++;
  send({ t: 'down', b: e.button, ...clampPosition(position(e)) });
});
canvas.addEventListener('pointermove', (e) => {
  if (e.pointerType === 'touch') return touchMove(e);
  if (buttonsDown === 0) return;
  pendingMove = clampPosition(position(e));
  scheduleFlush();
});
const release = (e) => {
  if (e.pointerType === 'touch') return touchUp(e);
  if (toolRelease(e)) return;
  if (e.button > 2 || buttonsDown === 0) return;
  flush();
  buttonsDown--;
  send({ t: 'up', b: e.button, ...clampPosition(position(e)) });
};
canvas.addEventListener('pointerup', release);
canvas.addEventListener('pointercancel', release);
canvas.addEventListener('dblclick', (e) => send({ t: 'dblclick', ...clampPosition(position(e)) }));
canvas.addEventListener('contextmenu', (e) => e.preventDefault());
canvas.addEventListener('wheel', (e) => {
  e.preventDefault();
  // One notch of a mouse wheel is about 100 pixels (3 lines) in Chromium and Firefox: one step.
  const perStep = e.deltaMode === 1 ? 3 : e.deltaMode === 2 ? 1 : 100;
  wheelAt(clampPosition(position(e)), -e.deltaY / perStep);
}, { passive: false });

// --- keys -----------------------------------------------------------------------------------------------

function typing(e) {
  const t = e.target;
  return t instanceof HTMLInputElement || t instanceof HTMLSelectElement || t instanceof HTMLTextAreaElement;
}

window.addEventListener('keydown', (e) => {
  const key = KEYS[e.code];
  if (!key || typing(e) || e.ctrlKey || e.altKey || e.metaKey) return;
  e.preventDefault();
  if (e.repeat) return; // the server keeps held keys held
  if (FLY.has(key)) heldKeys.add(key);
  send({ t: 'key', key, down: true, shift: e.shiftKey });
});
window.addEventListener('keyup', (e) => {
  const key = KEYS[e.code];
  if (!key || !FLY.has(key)) return;
  heldKeys.delete(key);
  send({ t: 'key', key, down: false });
});
window.addEventListener('blur', () => {
  for (const key of heldKeys) send({ t: 'key', key, down: false });
  heldKeys.clear();
});

connect();

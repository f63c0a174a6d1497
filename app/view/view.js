// fieldpath view: the page's data and its three.js scene (app/view/view.js, inlined by
// `fieldpath view` after colours.js and geometry.js, before panel.js and state.js; page.html wraps
// the three in one function, so they share their names and 'use strict').
// Reads #fp-meta (JSON: what is shown, counts, array references) and #fp-blob (base64: the typed
// arrays) and builds the scene (z up, millimetres): the renderer, camera and views, the meshes, the
// path and its colour modes, the tool + holder, the surface and the axes. panel.js builds the
// controls around it; state.js renders on demand and writes the page's state into #fp-state (JSON)
// after every frame: a test reads it with `chromium --dump-dom`.
// Location hash (for tests and links), '&' between: posture=N (posture index in the path file,
// 0-based; default: the least clearance), play (start playing), probe=M (also report the tool's
// screen box at postures N and M), colour=tilt|lead|clearance, view=iso|top|front|side|X,Y,Z (the
// direction the camera looks from), frame=scene|path, translucent,
// hide=part,obstacles,surface,path,links,marks,tool,axes, size=WxH (a fixed canvas: the same
// pixels whatever the window), quality | fast (multisampling and per-pixel lighting, or neither;
// default: neither on a software renderer, e.g. headless Chromium's SwiftShader).
var t0 = performance.now();
var meta = JSON.parse(document.getElementById('fp-meta').textContent);
var blob = decodeBase64(document.getElementById('fp-blob').textContent);
var hash = parseHash();
var state = { ready: false, errors: window.fpErrors, timings_ms: {} };
function mark(name) { state.timings_ms[name] = Math.round(performance.now()); }
mark('script');

// ---------------------------------------------------------------- data
function decodeBase64(text) {
  var binary = atob(text.replace(/\s+/g, ''));
  var bytes = new Uint8Array(binary.length);
  for (var i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
  return bytes;
}
var ARRAY_TYPES = { f32: Float32Array, u32: Uint32Array, u16: Uint16Array, u8: Uint8Array };
function arr(ref) {
  if (!ref) return null;
  var Type = ARRAY_TYPES[ref.type];
  return new Type(blob.buffer, ref.offset, ref.count);
}
function parseHash() {
  var out = {};
  location.hash.replace(/^#/, '').split('&').forEach(function (kv) {
    if (!kv) return;
    var at = kv.indexOf('=');
    out[decodeURIComponent(at < 0 ? kv : kv.slice(0, at))] =
        at < 0 ? '' : decodeURIComponent(kv.slice(at + 1));
  });
  return out;
}
var hidden = {};
(hash.hide || '').split(',').forEach(function (k) { if (k) hidden[k] = true; });

// ---------------------------------------------------------------- colours (colours.js)
var sequential = fpColours.sequential, clearanceMap = fpColours.clearanceMap,
    deviationMap = fpColours.deviationMap, withUncut = fpColours.withUncut,
    niceStep = fpColours.niceStep, fmt = fpColours.fmt, NO_VALUE = fpColours.NO_VALUE;

// ---------------------------------------------------------------- renderer
/// True where WebGL is drawn by the CPU (SwiftShader, llvmpipe): no multisampling and per-vertex
/// lighting there, so that the first frame comes within 2 s on two cores.
function softwareGL() {
  if ('quality' in hash) return false;
  if ('fast' in hash) return true;
  var gl = document.createElement('canvas').getContext('webgl');
  if (!gl) return false;
  var info = gl.getExtension('WEBGL_debug_renderer_info');
  var name = info ? String(gl.getParameter(info.UNMASKED_RENDERER_WEBGL)) : '';
  var lose = gl.getExtension('WEBGL_lose_context');
  if (lose) lose.loseContext();
  return /swiftshader|llvmpipe|softpipe|software/i.test(name);
}
var view = document.getElementById('fp-view');
var fixedSize = /^(\d+)x(\d+)$/.exec(hash.size || '');
if (fixedSize) {  // a fixed canvas: the same pixels whatever the window (tests compare runs)
  view.style.flex = 'none';
  view.style.width = fixedSize[1] + 'px';
  view.style.height = fixedSize[2] + 'px';
}
var renderer;
try {
  var software = softwareGL();
  mark('probe');
  renderer = new THREE.WebGLRenderer({ antialias: !software, preserveDrawingBuffer: true });
} catch (e) {
  showBanner(['WebGL is not available in this browser: ' + e.message]);
  state.webgl = false;
  writeState();
  throw e;
}
state.webgl = true;
/// Per-pixel lighting (Phong) on a GPU, per-vertex (Lambert) on a software renderer.
function shaded(params, shininess, specular) {
  if (software) return new THREE.MeshLambertMaterial(params);
  var m = new THREE.MeshPhongMaterial(params);
  m.shininess = shininess;
  m.specular.setHex(specular);
  return m;
}
state.software_gl = software;
state.context_ms = Math.round(performance.now() - t0);  // creating the WebGL context
mark('context');
renderer.setPixelRatio(window.devicePixelRatio || 1);
renderer.setClearColor(0x1d2127);
view.insertBefore(renderer.domElement, view.firstChild);
var scene = new THREE.Scene();
var box = new THREE.Box3(new THREE.Vector3().fromArray(meta.box.min),
                         new THREE.Vector3().fromArray(meta.box.max));
var centre = box.getCenter(new THREE.Vector3());
var radius = Math.max(1, box.getSize(new THREE.Vector3()).length() / 2);
var camera = new THREE.PerspectiveCamera(35, 1, radius / 200, radius * 40);
camera.up.set(0, 0, 1);
scene.add(camera);
scene.add(new THREE.HemisphereLight(0xf0f4ff, 0x30302a, 0.55));
var sun = new THREE.DirectionalLight(0xffffff, 0.75);
sun.position.set(0.4, 0.8, 1);
camera.add(sun);  // a light over the viewer's shoulder: every visible face is lit
var controls = new THREE.OrbitControls(camera, renderer.domElement);
controls.target.copy(centre);
controls.addEventListener('change', requestRender);
var VIEWS = { iso: [-0.55, -1.0, 1.9], top: [0, -0.001, 1], front: [0, -1, 0.02], side: [1, 0, 0.02] };
var frames = { scene: { centre: centre, radius: radius } };
var frame = 'scene';
/// Looks at frames[frame] (the scene's meshes, or the path's passes) from a direction of VIEWS.
function setView(name) {
  var custom = /^(-?[\d.]+),(-?[\d.]+),(-?[\d.]+)$/.exec(name || '');  // #view=x,y,z
  var d = new THREE.Vector3().fromArray(custom ? custom.slice(1).map(Number) : VIEWS[name] || VIEWS.iso)
      .normalize(), f = frames[frame];
  var distance = 1.1 * f.radius / Math.sin(17.5 * Math.PI / 180);  // the sphere in view
  camera.position.copy(f.centre).addScaledVector(d, distance);
  controls.target.copy(f.centre);
  camera.lookAt(f.centre);
  controls.update();
}

// ---------------------------------------------------------------- meshes
var layers = {};  // name → { object, label }
var meshObjects = [];
function decodeMesh(m) {
  return fpGeometry.meshGeometry(m, arr(m.positions), arr(m.indices));
}
var PART_COLOUR = 0xc9a26b, OBSTACLE_COLOUR = 0x7d9cc0;
meta.meshes.forEach(function (m, i) {
  var material = shaded({ color: m.role === 'part' ? PART_COLOUR : OBSTACLE_COLOUR,
                          side: THREE.DoubleSide }, 25, 0x222222);
  var mesh = new THREE.Mesh(decodeMesh(m), material);
  mesh.name = m.name;
  scene.add(mesh);
  meshObjects.push({ mesh: mesh, meta: m });
  layers['mesh' + i] = { object: mesh, label: m.name, role: m.role,
                         count: m.triangles + ' triangles' +
                                (m.triangles < m.source_triangles ? ' of ' + m.source_triangles : '') };
});

mark('meshes');
// ---------------------------------------------------------------- path
var path = meta.path, P = null;
if (path) {
  P = { tip: arr(path.tip), axis: arr(path.axis), index: arr(path.index), flags: arr(path.flags),
        pass: arr(path.pass), s: arr(path.s_mm), tilt: arr(path.tilt_deg), lead: arr(path.lead_deg),
        clearance: arr(path.clearance_mm), motion: arr(path.motion_mm), line: arr(path.line),
        n: path.shown };
  P.centre = new Float32Array(3 * P.n);
  for (var i = 0; i < 3 * P.n; ++i)
    P.centre[i] = P.tip[i] + path.offset_mm * P.axis[i];
  P.count = function (bit) {
    var c = 0;
    for (var i = 0; i < P.n; ++i) c += (P.flags[i] & bit) ? 1 : 0;
    return c;
  };
}
var F_LINK = 1, F_LIMITED = 2, F_COLLIDING = 4, F_MOTION_COLLIDING = 8, F_BLOCK_START = 16,
    F_PART = 32, F_MOTION_PART = 64;  // a link or the holder touching the part (not an obstacle)
var PART_MARK_COLOUR = 0xe040fb;      // postures and motions touching the part
var colourModes = {};
if (P) {
  var range = function (values) {
    var lo = Infinity, hi = -Infinity;
    for (var i = 0; i < P.n; ++i)
      if (isFinite(values[i])) { lo = Math.min(lo, values[i]); hi = Math.max(hi, values[i]); }
    if (!isFinite(lo)) return null;
    if (hi - lo < 1e-6) { lo -= 0.5; hi += 0.5; }
    return [lo, hi];
  };
  var tiltRange = range(P.tilt), leadRange = range(P.lead), clearRange = range(P.clearance);
  if (tiltRange) colourModes.tilt = { title: 'tilt, deg', values: P.tilt, lo: tiltRange[0],
                                      hi: tiltRange[1], map: sequential(tiltRange[0], tiltRange[1]) };
  if (leadRange) colourModes.lead = { title: 'lead, deg', values: P.lead, lo: leadRange[0],
                                      hi: leadRange[1], map: sequential(leadRange[0], leadRange[1]) };
  if (clearRange) {
    var req = path.required_mm, hiC = Math.max(4 * req, Math.min(clearRange[1], 10 * Math.max(req, 0.5)));
    colourModes.clearance = { title: 'clearance, mm (required ' + req + ')', values: P.clearance,
                              lo: 0, hi: hiC, map: clearanceMap(req, hiC), required: req };
  }
}
var colourMode = hash.colour in colourModes ? hash.colour
                 : 'tilt' in colourModes ? 'tilt' : Object.keys(colourModes)[0];

var passLine = null, passDots = null, linkLine = null, markGroup = null;
function sameBlock(j) { return !(P.flags[j + 1] & F_BLOCK_START); }
function buildPath() {
  var pass = [], link = [], hit = [], partHit = [];
  for (var j = 0; j + 1 < P.n; ++j) {
    var isPass = sameBlock(j) && !(P.flags[j] & F_LINK);
    (isPass ? pass : link).push(j);
    if ((P.flags[j] & F_MOTION_COLLIDING) && P.index[j + 1] === P.index[j] + 1) hit.push(j);
    if ((P.flags[j] & F_MOTION_PART) && P.index[j + 1] === P.index[j] + 1) partHit.push(j);
  }
  function segments(list) {
    var pos = new Float32Array(6 * list.length);
    list.forEach(function (j, k) {
      for (var c = 0; c < 3; ++c) {
        pos[6 * k + c] = P.centre[3 * j + c];
        pos[6 * k + 3 + c] = P.centre[3 * j + 3 + c];
      }
    });
    var g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    return g;
  }
  var g = segments(pass);
  g.setAttribute('color', new THREE.BufferAttribute(new Float32Array(6 * pass.length), 3));
  passLine = new THREE.LineSegments(g, new THREE.LineBasicMaterial({ vertexColors: THREE.VertexColors }));
  passLine.userData.list = pass;
  // The pass postures also as dots: a 1-pixel line alone hardly shows its colour.
  var dots = [];
  for (var j = 0; j < P.n; ++j) if (!(P.flags[j] & F_LINK)) dots.push(j);
  var pg = new THREE.BufferGeometry(), pp = new Float32Array(3 * dots.length);
  dots.forEach(function (j, k) { for (var c = 0; c < 3; ++c) pp[3 * k + c] = P.centre[3 * j + c]; });
  pg.setAttribute('position', new THREE.BufferAttribute(pp, 3));
  pg.setAttribute('color', new THREE.BufferAttribute(new Float32Array(3 * dots.length), 3));
  passDots = new THREE.Points(pg, new THREE.PointsMaterial({
    vertexColors: THREE.VertexColors, size: 3, sizeAttenuation: false }));
  passDots.userData.list = dots;
  var pathGroup = new THREE.Group();
  pathGroup.add(passLine, passDots);
  scene.add(pathGroup);
  linkLine = new THREE.LineSegments(segments(link),
      new THREE.LineDashedMaterial({ color: 0xb8c0cc, dashSize: radius / 120, gapSize: radius / 160 }));
  linkLine.computeLineDistances();
  scene.add(linkLine);
  layers.path = { object: pathGroup, label: 'path (ball centres)', count: P.n + ' postures' };
  layers.links = { object: linkLine, label: 'links', count: path.counts.links + ' links' };

  markGroup = new THREE.Group();
  function points(bit, colour, size) {
    var list = [];
    for (var j = 0; j < P.n; ++j) if (P.flags[j] & bit) list.push(j);
    var pos = new Float32Array(3 * list.length);
    list.forEach(function (j, k) { for (var c = 0; c < 3; ++c) pos[3 * k + c] = P.centre[3 * j + c]; });
    var geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    // Each mark on a dark dot 3 px wider: a red mark over the red end of the deviation scale
    // (large scallops) was hard to see.
    var rim = new THREE.Points(geometry, new THREE.PointsMaterial({
      color: 0x101418, size: size + 3, sizeAttenuation: false, depthTest: false }));
    rim.renderOrder = 10;
    var p = new THREE.Points(geometry, new THREE.PointsMaterial({
      color: colour, size: size, sizeAttenuation: false, depthTest: false }));
    p.renderOrder = 11;
    markGroup.add(rim, p);
    return list.length;
  }
  points(F_LIMITED, 0xff9f1c, 7);
  points(F_COLLIDING, 0xff2a1a, 6);
  points(F_PART, PART_MARK_COLOUR, 6);
  [[hit, 0xff2a1a], [partHit, PART_MARK_COLOUR]].forEach(function(h) {
    if (!h[0].length) return;
    var motionLines = new THREE.LineSegments(segments(h[0]),
        new THREE.LineBasicMaterial({ color: h[1], depthTest: false }));
    motionLines.renderOrder = 9;
    markGroup.add(motionLines);
  });
  scene.add(markGroup);
  layers.marks = { object: markGroup, label: 'collisions, limits', count: '' };
}
function colourPath() {
  if (!passLine) return;
  var mode = colourModes[colourMode], colours = passLine.geometry.attributes.color.array;
  passLine.userData.list.forEach(function (j, k) {
    var a = mode ? mode.map(mode.values[j]) : NO_VALUE, b = mode ? mode.map(mode.values[j + 1]) : NO_VALUE;
    colours.set(a, 6 * k);
    colours.set(b, 6 * k + 3);
  });
  passLine.geometry.attributes.color.needsUpdate = true;
  var dotColours = passDots.geometry.attributes.color.array;
  passDots.userData.list.forEach(function (j, k) {
    dotColours.set(mode ? mode.map(mode.values[j]) : NO_VALUE, 3 * k);
  });
  passDots.geometry.attributes.color.needsUpdate = true;
}
if (P) {
  buildPath();
  colourPath();
  var passBox = new THREE.Box3(), v = new THREE.Vector3();
  for (var j = 0; j < P.n; ++j)
    if (!(P.flags[j] & F_LINK)) passBox.expandByPoint(v.fromArray(P.centre, 3 * j));
  if (!passBox.isEmpty()) {
    var pr = passBox.getSize(new THREE.Vector3()).length() / 2;
    frames.path = { centre: passBox.getCenter(new THREE.Vector3()),
                    radius: Math.max(pr * 1.15, radius / 20) };
    // The passes' region when it is a small part of the scene (one channel of a wheel).
    if (frames.path.radius < 0.6 * radius) frame = 'path';
  }
}
if (hash.frame in frames) frame = hash.frame;

mark('path');
// ---------------------------------------------------------------- tool + holder
var tool = null;
(function() {
  var t = meta.tool, built = fpGeometry.toolGeometry(t, arr(t.positions), arr(t.indices));
  tool = new THREE.Mesh(built.geometry, shaded({vertexColors: THREE.VertexColors}, 60, 0x444444));
  tool.visible = !!P;
  tool.userData.top = built.top;  // the top of tool + holder on its axis (mm): the page's state
  scene.add(tool);
  layers.tool = {
    object: tool,
    label: 'tool + holder',
    count: t.triangles + ' triangles'
  };
})();

// ---------------------------------------------------------------- surface
var surface = meta.surface, surfaceMap = null;
if (surface) {
  (function() {
    var s = surface;
    surfaceMap = s.kind === 'deviation' ? deviationMap(s.range[0], s.range[1], s.uncut_um)
                                        : withUncut(sequential(s.range[0], s.range[1]), s.uncut_um);
    var built = fpGeometry.surfaceGeometry(s, arr(s.height), arr(s.value), surfaceMap),
        g = built.geometry;
    var mesh = new THREE.Mesh(g, shaded({ vertexColors: THREE.VertexColors, side: THREE.DoubleSide },
                                        10, 0x111111));
    scene.add(mesh);
    layers.surface = {
      object: mesh,
      label: 'machined surface',
      count: built.triangles + ' triangles'
    };
    // The simulated surface lies on the part: the part is drawn behind it where they meet.
    meshObjects.forEach(function (o) {
      if (o.meta.role !== 'part') return;
      o.mesh.material.polygonOffset = true;
      o.mesh.material.polygonOffsetFactor = 2;
      o.mesh.material.polygonOffsetUnits = 4;
    });
  })();
}

mark('surface');
// ---------------------------------------------------------------- axes, millimetres
var axes;
(function() {
  var size = box.getSize(new THREE.Vector3()), step = niceStep(Math.max(size.x, size.y, size.z), 5);
  axes = fpGeometry.axesGroup(box, step);
  scene.add(axes);
  layers.axes = {
    object: axes,
    label: 'axes (mm)',
    count: 'ticks every ' + step + ' mm'
  };
})();

mark('axes');

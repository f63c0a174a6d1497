// fieldpath view: the page's script (app/view/view.js, inlined by `fieldpath view`).
// Reads #fp-meta (JSON: what is shown, counts, array references) and #fp-blob (base64: the typed
// arrays), builds a three.js scene (z up, millimetres), renders on demand, and writes its state
// into #fp-state (JSON) after every frame: a test reads it with `chromium --dump-dom`.
// Location hash (for tests and links), '&' between: posture=N (posture index in the path file,
// 0-based; default: the least clearance), play (start playing), probe=M (also report the tool's
// screen box at postures N and M), colour=tilt|lead|clearance, view=iso|top|front|side|X,Y,Z (the
// direction the camera looks from), frame=scene|path, translucent,
// hide=part,obstacles,surface,path,links,marks,tool,axes, size=WxH (a fixed canvas: the same
// pixels whatever the window), quality | fast (multisampling and per-pixel lighting, or neither;
// default: neither on a software renderer, e.g. headless Chromium's SwiftShader).
(function () {
  'use strict';
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
  var PART_COLOUR = 0xe040fb;
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
    points(F_PART, PART_COLOUR, 6);
    [[hit, 0xff2a1a], [partHit, PART_COLOUR]].forEach(function (h) {
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

  mark('path');
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
  // ---------------------------------------------------------------- side panel
  var side = document.getElementById('fp-side');
  function el(tag, attrs, parent, text) {
    var e = document.createElement(tag);
    for (var k in attrs) e.setAttribute(k, attrs[k]);
    if (text !== undefined) e.textContent = text;
    if (parent) parent.appendChild(e);
    return e;
  }
  el('h1', {}, side, 'fieldpath view');
  el('div', { class: 'sub' }, side, meta.scene);
  if (path) el('div', { class: 'sub' }, side, path.file);
  el('h2', {}, side, 'Show');
  var translucent = false;
  Object.keys(layers).forEach(function (key) {
    var layer = layers[key], lab = el('label', { title: layer.label + ' ' + layer.count }, side);
    var box = el('input', { type: 'checkbox', id: 'fp-show-' + key }, lab);
    var hideKey = key === 'path' ? 'path' : layer.role === 'part' ? 'part'
                  : layer.role === 'obstacle' ? 'obstacles' : key;
    if (hidden[hideKey]) layer.object.visible = false;
    if (key === 'tool' && !P) layer.object.visible = false;
    box.checked = layer.object.visible;
    box.addEventListener('change', function () {
      layer.object.visible = box.checked;
      drawLegends();
      requestRender();
    });
    lab.appendChild(document.createTextNode(' ' + layer.label + ' '));
    el('span', { class: 'count' }, lab, layer.count ? '(' + layer.count + ')' : '');
  });
  var lab = el('label', {}, side), tbox = el('input', { type: 'checkbox', id: 'fp-translucent' }, lab);
  lab.appendChild(document.createTextNode(' translucent meshes'));
  tbox.addEventListener('change', applyTranslucent);
  if ('translucent' in hash) {
    tbox.checked = true;
    applyTranslucent();
  }
  function applyTranslucent() {
    translucent = tbox.checked;
    meshObjects.forEach(function (o) {
      o.mesh.material.transparent = translucent;
      o.mesh.material.opacity = translucent ? 0.35 : 1;
      o.mesh.material.depthWrite = !translucent;
      o.mesh.material.needsUpdate = true;
    });
    requestRender();
  }
  if (Object.keys(colourModes).length) {
    el('h2', {}, side, 'Colour the path by');
    var select = el('select', { id: 'fp-colour' }, side);
    Object.keys(colourModes).forEach(function (k) {
      var o = el('option', { value: k }, select, k);
      if (k === colourMode) o.selected = true;
    });
    select.addEventListener('change', function () {
      colourMode = select.value; colourPath(); drawLegends(); requestRender();
    });
  }
  el('h2', {}, side, 'View');
  var views = el('div', {}, side);
  Object.keys(VIEWS).forEach(function (k) {
    el('button', {}, views, k).addEventListener('click', function () { setView(k); requestRender(); });
  });
  var frameRow = el('div', {}, side);
  Object.keys(frames).forEach(function (k) {
    var lab = el('label', { style: 'display:inline' }, frameRow);
    var r = el('input', { type: 'radio', name: 'fp-frame', value: k }, lab);
    r.checked = k === frame;
    r.addEventListener('change', function () { frame = k; setView('iso'); requestRender(); });
    lab.appendChild(document.createTextNode(' ' + (k === 'scene' ? 'whole scene ' : 'passes ')));
  });
  if (path) {
    el('h2', {}, side, 'Path');
    var c = path.counts, rows = [
      ['postures', c.postures + (path.shown < c.postures ? ' (' + path.shown + ' shown)' : '')],
      ['passes / links', c.passes + ' / ' + c.links],
      ['colliding postures', P.count(F_COLLIDING)], ['colliding motions', P.count(F_MOTION_COLLIDING)],
      ['angle limit held', P.count(F_LIMITED)]];
    if (c.part_contact_postures !== null && c.part_contact_postures !== undefined)
      rows.push([
        'touching the part (links, holder, cutter)',
        P.count(F_PART) + ' postures, ' + P.count(F_MOTION_PART) + ' motions'
      ]);
    if (c.postures_under_required || c.motions_under_required)
      rows.push([
        'under the required clearance',
        c.postures_under_required + ' postures, ' + c.motions_under_required + ' motions'
      ]);
    rows.forEach(function (r) { el('div', {}, side, r[0] + ': ' + r[1]); });
    el('div', { class: 'sub' }, side, 'clearance: ' + path.clearance_source);
    el('div', { class: 'sub' }, side, 'tilt, lead: ' + path.angles_source);
  }
  if (surface) {
    el('h2', {}, side, 'Surface');
    el('div', { class: 'sub' }, side, surface.source);
  }
  (meta.notes || []).forEach(function (n) { el('div', { class: 'sub' }, side, n); });
  var banner = (meta.missing || []).concat(meta.warnings || []);
  if (banner.length) showBanner(banner);
  function showBanner(lines) {
    var b = document.getElementById('fp-banner');
    b.hidden = false;
    lines.forEach(function (t) { el('div', {}, b, t); });
  }

  // ---------------------------------------------------------------- legends
  var legends = document.getElementById('fp-legends');
  function legend(title, lo, hi, map, unit, id) {
    var box = el('div', { class: 'fp-legend', id: id }, legends);
    el('div', {}, box, title);
    var canvas = el('canvas', { width: 180, height: 10 }, box), ctx = canvas.getContext('2d');
    for (var x = 0; x < 180; ++x) {
      var c = map(lo + (hi - lo) * (x + 0.5) / 180) || NO_VALUE;
      ctx.fillStyle = 'rgb(' + Math.round(255 * c[0]) + ',' + Math.round(255 * c[1]) + ',' +
                      Math.round(255 * c[2]) + ')';
      ctx.fillRect(x, 0, 1, 10);
    }
    var ticks = el('div', { class: 'ticks' }, box);
    var digits = Math.max(0, Math.min(3, 2 - Math.floor(Math.log10(Math.max(1e-9, hi - lo)))));
    [lo, (lo + hi) / 2, hi].forEach(function (v) { el('span', {}, ticks, fmt(v, digits)); });
    if (unit) el('div', { class: 'sub' }, box, unit);
  }
  function drawLegends() {
    legends.textContent = '';
    var mode = colourModes[colourMode];
    if (mode && layers.path.object.visible)
      legend('path: ' + mode.title, mode.lo, mode.hi, mode.map, '', 'fp-legend-path');
    if (P && layers.marks.object.visible) {
      var marks = el('div', { class: 'fp-legend fp-marks', id: 'fp-legend-marks' }, legends);
      var kinds = [['#ff2a1a', 'colliding posture / motion'], ['#ff9f1c', 'angle limit held'],
                   ['#b8c0cc', 'link (dashed)']];
      if (P.count(F_PART) + P.count(F_MOTION_PART) > 0)
        kinds.splice(1, 0, ['#e040fb', 'touching the part: link, holder, or cutter (gouge)']);
      kinds.forEach(function (m) {
        var row = el('div', {}, marks);
        el('span', { style: 'background:' + m[0] }, row);
        row.appendChild(document.createTextNode(m[1]));
      });
    }
    if (surface && layers.surface.object.visible) {
      var s = surface;
      legend(
          s.kind === 'deviation' ? 'surface: deviation, \u00b5m (gouge < 0 < scallop)' :
                                   'surface: height, mm',
          s.range[0], s.range[1], surfaceMap,
          [
            s.kind === 'deviation' ? 'purple: above the scale (stock left beside the band)' : '',
            s.uncut_um ? 'grey: not cut' +
                    (s.uncut_um < 1e6 ? ' (' + Math.round(s.uncut_um) + ' \u00b5m of stock left)' :
                                        '') :
                         ''
          ]
              .filter(function(t) {
                return t;
              })
              .join('; '),
          'fp-legend-surface');
    }
  }
  drawLegends();

  // ---------------------------------------------------------------- timeline
  var timeline = document.getElementById('fp-timeline');
  var current = 0, playing = null, slider = null, posLabel = null;
  if (P) {
    var back = el('button', { id: 'fp-back', title: 'previous posture' }, timeline, '\u25c0');
    var play = el('button', { id: 'fp-play', title: 'play / pause' }, timeline, '\u25b6');
    var fwd = el('button', { id: 'fp-forward', title: 'next posture' }, timeline, '\u25b6|');
    slider = el('input', { type: 'range', id: 'fp-slider', min: 0, max: P.n - 1, value: 0, step: 1 }, timeline);
    posLabel = el('span', { class: 'pos' }, timeline);
    slider.addEventListener('input', function () { setPosture(+slider.value); });
    back.addEventListener('click', function () { setPosture(current - 1); });
    fwd.addEventListener('click', function () { setPosture(current + 1); });
    play.addEventListener('click', togglePlay);
    function togglePlay() {
      if (playing) { clearInterval(playing); playing = null; play.textContent = '\u25b6'; return; }
      var stride = Math.max(1, Math.round(P.n / 900));
      play.textContent = '\u275a\u275a';
      playing = setInterval(function () {
        if (current + stride > P.n - 1) { clearInterval(playing); playing = null; play.textContent = '\u25b6'; }
        setPosture(Math.min(P.n - 1, current + stride));
      }, 33);
    }
  } else {
    el('span', {}, timeline, 'no path');
    document.getElementById('fp-info').hidden = true;
  }
  function shownIndexOf(posture) {  // the shown posture nearest to a path index
    var lo = 0, hi = P.n - 1;
    while (lo < hi) {
      var mid = (lo + hi) >> 1;
      if (P.index[mid] < posture) lo = mid + 1; else hi = mid;
    }
    if (lo > 0 && Math.abs(P.index[lo - 1] - posture) <= Math.abs(P.index[lo] - posture)) --lo;
    return lo;
  }
  /// The posture of least clearance (the first colliding one), else the first of a pass.
  function closestPosture() {
    var best = -1;
    for (var j = 0; j < P.n; ++j)
      if (isFinite(P.clearance[j]) && (best < 0 || P.clearance[j] < P.clearance[best])) best = j;
    if (best >= 0) return best;
    for (j = 0; j < P.n; ++j) if (!(P.flags[j] & F_LINK)) return j;
    return 0;
  }
  var q = new THREE.Quaternion(), Z = new THREE.Vector3(0, 0, 1), a = new THREE.Vector3();
  function placeTool(j) {
    a.set(P.axis[3 * j], P.axis[3 * j + 1], P.axis[3 * j + 2]).normalize();
    q.setFromUnitVectors(Z, a);
    tool.quaternion.copy(q);
    tool.position.set(P.tip[3 * j], P.tip[3 * j + 1], P.tip[3 * j + 2]);
    tool.updateMatrixWorld(true);
  }
  var info = document.getElementById('fp-info');
  function postureInfo(j) {
    var f = P.flags[j], c = P.clearance[j];
    var o = { index: P.index[j], block: (f & F_LINK) ? 'link' : 'pass', pass: (f & F_LINK) ? null : P.pass[j],
              line: P.line[j], s_mm: num(P.s[j]), tilt_deg: num(P.tilt[j]), lead_deg: num(P.lead[j]),
              clearance_mm: num(c), motion_to_next_mm: num(P.motion[j]),
              colliding: !!(f & F_COLLIDING), motion_colliding: !!(f & F_MOTION_COLLIDING),
              part_contact: !!(f & F_PART), motion_part_contact: !!(f & F_MOTION_PART),
              limited: !!(f & F_LIMITED),
              tip_mm: [P.tip[3 * j], P.tip[3 * j + 1], P.tip[3 * j + 2]],
              axis: [P.axis[3 * j], P.axis[3 * j + 1], P.axis[3 * j + 2]] };
    return o;
  }
  function num(v) { return isFinite(v) ? v : null; }
  function setPosture(j, quiet) {
    if (!P) return;
    current = Math.max(0, Math.min(P.n - 1, j));
    slider.value = current;
    placeTool(current);
    var o = postureInfo(current);
    tool.material.emissive.setHex(o.colliding || o.part_contact ? 0xaa1100 : 0x000000);
    posLabel.textContent = (o.index + 1) + ' / ' + path.counts.postures;
    var rows = [
      ['posture', o.index + ' (' + (path.rows ? 'row ' : 'line ') + o.line + ')'],
      ['block', o.block === 'link' ? 'link' : 'pass ' + o.pass],
      ['s', fmt(o.s_mm, 2) + ' mm'], ['tilt', fmt(o.tilt_deg, 2) + '\u00b0'],
      ['lead', fmt(o.lead_deg, 2) + '\u00b0'],
      ['clearance', fmt(o.clearance_mm, 3) + ' mm', o.colliding ? 'bad' :
                    o.clearance_mm !== null && o.clearance_mm < path.required_mm ? 'warn' : ''],
      ['to next', fmt(o.motion_to_next_mm, 3) + ' mm' + (o.motion_part_contact ? ' (part)' : ''),
       o.motion_colliding || o.motion_part_contact ? 'bad' : ''],
      ['tip', o.tip_mm.map(function (v) { return fmt(v, 2); }).join(' ') + ' mm'],
      ['axis', o.axis.map(function (v) { return fmt(v, 3); }).join(' ')]];
    // Whose the contact is: a link's posture is the link's; a pass posture's the holder's or the
    // cutter's (a gouge past the tolerance), told by check's counts where only one has any.
    function partContactWhose(o) {
      if (o.block === 'link') return 'link';
      var c = path.counts, holder = c.part_contact_holder > 0, cutter = c.part_contact_cutter > 0;
      return holder === cutter ? 'holder or cutter' : cutter ? 'cutter: gouge' : 'holder';
    }
    // One status row always: the panel keeps its size from posture to posture.
    rows.push(
        o.colliding        ? ['', o.limited ? 'COLLIDING, limit held' : 'COLLIDING', 'bad'] :
            o.part_contact ? ['', 'PART CONTACT (' + partContactWhose(o) + ')', 'bad'] :
            o.limited      ? ['', 'angle limit held', 'warn'] :
                             ['', '\u00a0']);
    info.textContent = '';
    var table = el('table', { id: 'fp-posture' }, info);
    rows.forEach(function (r) {
      var tr = el('tr', {}, table);
      el('td', {}, tr, r[0]);
      el('td', r[2] ? { class: r[2] } : {}, tr, r[1]);
    });
    state.posture = o;
    if (!quiet) {
      requestRender();
      writeState();
    }
  }

  // ---------------------------------------------------------------- rendering and state
  var pending = false;
  function resize() {
    var w = view.clientWidth, h = view.clientHeight;
    renderer.setSize(w, h);
    camera.aspect = w / Math.max(1, h);
    camera.updateProjectionMatrix();
  }
  function requestRender() {
    if (pending) return;
    pending = true;
    requestAnimationFrame(function () { pending = false; render(); });
  }
  function render() {
    renderer.render(scene, camera);
    writeState();
  }
  window.addEventListener('resize', function () { resize(); requestRender(); });

  /// Screen box [x0, y0, x1, y1] (CSS pixels of the page) of an object's vertices, clipped to the
  /// canvas; null when none is in view.
  function screenBox(object) {
    var rect = renderer.domElement.getBoundingClientRect();
    var p = object.geometry.attributes.position, v = new THREE.Vector3();
    var stride = Math.max(1, Math.floor(p.count / 4000)), b = [Infinity, Infinity, -Infinity, -Infinity];
    object.updateMatrixWorld(true);
    for (var i = 0; i < p.count; i += stride) {
      v.fromBufferAttribute(p, i).applyMatrix4(object.matrixWorld).project(camera);
      if (v.z < -1 || v.z > 1) continue;
      var x = rect.left + (v.x + 1) / 2 * rect.width, y = rect.top + (1 - v.y) / 2 * rect.height;
      b = [Math.min(b[0], x), Math.min(b[1], y), Math.max(b[2], x), Math.max(b[3], y)];
    }
    if (!isFinite(b[0])) return null;
    b = [Math.max(b[0], rect.left), Math.max(b[1], rect.top), Math.min(b[2], rect.right),
         Math.min(b[3], rect.bottom)];
    return b[0] < b[2] && b[1] < b[3] ? b.map(Math.round) : null;
  }
  function rectOf(id) {
    var e = document.getElementById(id);
    if (!e || e.hidden || !e.offsetParent) return null;
    var r = e.getBoundingClientRect();
    return [Math.floor(r.left), Math.floor(r.top), Math.ceil(r.right), Math.ceil(r.bottom)];
  }
  function writeState() {
    state.ready = true;
    state.first_frame_ms = state.first_frame_ms || null;
    state.triangles = renderer.info.render.triangles;
    state.draw_calls = renderer.info.render.calls;
    state.canvas = rectOf('fp-view');
    state.overlays = ['fp-banner', 'fp-info', 'fp-legends', 'fp-errors'].map(rectOf)
        .filter(function (r) { return r; });
    state.meshes = meshObjects.map(function (o) {
      return { name: o.meta.name, role: o.meta.role, visible: o.mesh.visible,
               triangles: o.meta.triangles, screen_box: o.mesh.visible ? screenBox(o.mesh) : null };
    });
    state.part_box = null;
    state.meshes.forEach(function (m) { if (m.role === 'part' && m.screen_box) state.part_box = m.screen_box; });
    if (layers.surface) state.surface_box = screenBox(layers.surface.object);
    if (P) {
      state.postures = path.counts.postures;
      state.shown_postures = P.n;
      state.colliding_postures = P.count(F_COLLIDING);
      state.colliding_motions = P.count(F_MOTION_COLLIDING);
      state.part_contact_postures = P.count(F_PART);
      state.part_contact_motions = P.count(F_MOTION_PART);
      state.limited_postures = P.count(F_LIMITED);
      state.tool_box = tool.visible ? screenBox(tool) : null;
      if ('probe' in hash) {  // the tool's screen box at the first posture and at another
        var keep = current;
        [['start', shownIndexOf(+(hash.posture || 0))], ['probe', shownIndexOf(+hash.probe)]]
            .forEach(function (p) {
              placeTool(p[1]);
              // Where the tool stands in the world (mm): its tip and the top of its axis, for a
              // test against the path file (the screen box alone moves with a misplaced tool).
              state[p[0]] = {
                index: P.index[p[1]],
                tool_box: screenBox(tool),
                tip_mm: tool.localToWorld(new THREE.Vector3(0, 0, 0)).toArray(),
                top_mm: tool.localToWorld(new THREE.Vector3(0, 0, tool.userData.top)).toArray()
              };
            });
        placeTool(keep);
      }
      state.playing = !!playing;
    } else {
      state.postures = 0;
    }
    state.colour = colourMode || null;
    state.frame = frame;
    state.missing = meta.missing || [];
    state.warnings = meta.warnings || [];
    state.errors = window.fpErrors;
    document.getElementById('fp-state').textContent = JSON.stringify(state);
  }

  resize();
  setView(hash.view);
  if (P) setPosture('posture' in hash ? shownIndexOf(+hash.posture) : closestPosture(), true);
  mark('ui');
  renderer.compile(scene, camera);
  mark('compile');
  renderer.render(scene, camera);
  var gl = renderer.getContext();
  gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));  // waits for the frame
  state.first_frame_ms = Math.round(performance.now());
  state.build_ms = Math.round(performance.now() - t0);
  writeState();
  if (P && 'play' in hash) document.getElementById('fp-play').click();
})();

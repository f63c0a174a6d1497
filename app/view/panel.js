// fieldpath view: the page's controls and overlays (app/view/panel.js, inlined by `fieldpath view`
// after view.js, in its function scope: page.html): the side panel (layers shown, translucent
// meshes, the path's colour, views, frame, the path's counts), the banner, the colour legends, and
// the timeline with the posture panel (slider, play, the tool placed at a posture). Each control
// changes the scene of view.js and asks state.js for a frame.
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
  // Numbered from 0 as in the panel, the files and #posture= (README): "2 / 2346" beside
  // "posture 1" read as two postures.
  posLabel.textContent = 'posture ' + o.index + ' (0\u2013' + (path.counts.postures - 1) + ')';
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

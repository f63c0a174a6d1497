// fieldpath view: rendering and the page's state (app/view/state.js, inlined by `fieldpath view`
// last, in view.js's function scope: page.html): renders on demand, writes #fp-state (JSON, read by
// the tests) after every frame, and draws the first frame.
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
  if (!renderer) {  // no WebGL: nothing below was built; what the page says is the banner
    state.errors = window.fpErrors;
    document.getElementById('fp-state').textContent = JSON.stringify(state);
    return;
  }
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

// fieldpath view: the page's objects built from its arrays (app/view/geometry.js, inlined by
// `fieldpath view` before view.js): the meshes, the tool and holder, the machined surface and the
// axes as three.js objects, from the decoded arrays and the materials view.js gives; no page
// state (they were a hundred and twenty lines of view.js, which ran past 800).
var fpGeometry = (function() {
  'use strict';
  /// A scene mesh from its quantised positions `q` (m.origin + m.step * q, mm) and indices.
  function meshGeometry(m, q, indices) {
    var n = q.length / 3, p = new Float32Array(q.length);
    for (var i = 0; i < n; ++i)
      for (var k = 0; k < 3; ++k) p[3 * i + k] = m.origin[k] + m.step[k] * q[3 * i + k];
    var g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(p, 3));
    g.setIndex(new THREE.BufferAttribute(indices, 1));
    g.computeVertexNormals();
    g.computeBoundingSphere();
    return g;
  }

  /// The tool and holder on their axis (tip at 0, +z up, mm): the cutter (up to the tool's
  /// `length_mm`) in one colour, the holder in another; `top`: their highest point on the axis.
  function toolGeometry(t, p, indices) {
    var colours = new Float32Array(p.length);
    var toolColour = new THREE.Color(0xe8e2c8), holderColour = new THREE.Color(0x6e7682);
    for (var i = 0; i < p.length / 3; ++i)
      (p[3 * i + 2] <= t.length_mm + 1e-6 ? toolColour : holderColour).toArray(colours, 3 * i);
    var g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(p, 3));
    g.setAttribute('color', new THREE.BufferAttribute(colours, 3));
    g.setIndex(new THREE.BufferAttribute(indices, 1));
    g.computeVertexNormals();
    var top = 0;
    for (var k = 2; k < p.length; k += 3) top = Math.max(top, p[k]);
    return {geometry: g, top: top};
  }

  /// The machined surface: a grid of `s.nx` x `s.ny` cells of heights `h` coloured by `map`
  /// of their values `v`; cells without a height or a colour (null) are left out.
  function surfaceGeometry(s, h, v, map) {
    var nx = s.nx, ny = s.ny;
    var pos = new Float32Array(3 * nx * ny), col = new Float32Array(3 * nx * ny);
    var ok = new Uint8Array(nx * ny);
    for (var iy = 0; iy < ny; ++iy)
      for (var ix = 0; ix < nx; ++ix) {
        var k = iy * nx + ix, c = map(v[k]);
        pos[3 * k] = s.x0 + (ix + 0.5) * s.dx;
        pos[3 * k + 1] = s.y0 + (iy + 0.5) * s.dy;
        pos[3 * k + 2] = isFinite(h[k]) ? h[k] : 0;
        ok[k] = isFinite(h[k]) && c !== null ? 1 : 0;
        if (c) col.set(c, 3 * k);
      }
    var index = [];
    for (var iy = 0; iy + 1 < ny; ++iy)
      for (var ix = 0; ix + 1 < nx; ++ix) {
        var a = iy * nx + ix, b = a + 1, c = a + nx, d = c + 1;
        if (ok[a] && ok[b] && ok[d]) index.push(a, b, d);
        if (ok[a] && ok[d] && ok[c]) index.push(a, d, c);
      }
    var g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    g.setAttribute('color', new THREE.BufferAttribute(col, 3));
    g.setIndex(
        nx * ny > 65535 ? new THREE.Uint32BufferAttribute(index, 1) :
                          new THREE.Uint16BufferAttribute(index, 1));
    g.computeVertexNormals();
    return {geometry: g, triangles: index.length / 3};
  }

  /// A text sprite `height` mm tall at `at`, drawn over everything.
  function label(text, at, height, colour) {
    var canvas = document.createElement('canvas'), ctx = canvas.getContext('2d');
    var px = 28;
    ctx.font = px + 'px sans-serif';
    canvas.width = Math.ceil(ctx.measureText(text).width) + 8;
    canvas.height = px + 8;
    ctx.font = px + 'px sans-serif';
    ctx.fillStyle =
        '#' + new THREE.Color(colour).lerp(new THREE.Color(0xffffff), 0.45).getHexString();
    ctx.textBaseline = 'middle';
    ctx.fillText(text, 4, canvas.height / 2);
    var texture = new THREE.CanvasTexture(canvas);
    texture.minFilter = THREE.LinearFilter;
    var sprite = new THREE.Sprite(new THREE.SpriteMaterial({map: texture, depthTest: false}));
    sprite.scale.set(height * canvas.width / canvas.height, height, 1);
    sprite.position.copy(at);
    sprite.renderOrder = 20;
    return sprite;
  }

  /// Axes x, y, z round the box `box` (mm) with ticks every `step` mm, labelled.
  function axesGroup(box, step) {
    var axes = new THREE.Group();
    var o = new THREE.Vector3(
        Math.floor(box.min.x / step) * step, Math.floor(box.min.y / step) * step,
        Math.floor(box.min.z / step) * step);
    var ends = [
      Math.ceil(box.max.x / step) * step, Math.ceil(box.max.y / step) * step,
      Math.ceil(box.max.z / step) * step
    ];
    var COLOURS = [0xe45756, 0x54a24b, 0x4c78a8], NAMES = ['x', 'y', 'z'];
    var labelSize = step * 0.32;
    for (var k = 0; k < 3; ++k) {
      var tickDir = new THREE.Vector3();
      tickDir.setComponent(k === 0 ? 1 : 0, -1);
      var start = o.getComponent(k), pts = [];
      var a = o.clone(), b = o.clone();
      b.setComponent(k, ends[k]);
      pts.push(a, b);
      for (var x = start; x <= ends[k] + 1e-9; x += step) {
        var p = o.clone();
        p.setComponent(k, x);
        pts.push(p, p.clone().addScaledVector(tickDir, step * 0.12));
        var last = x + step > ends[k] + 1e-9;
        axes.add(label(
            last ? (x.toFixed(step < 1 ? 2 : 0) + ' mm ' + NAMES[k]) : x.toFixed(step < 1 ? 2 : 0),
            p.clone().addScaledVector(tickDir, step * 0.3), labelSize, COLOURS[k]));
      }
      var g = new THREE.BufferGeometry().setFromPoints(pts);
      axes.add(new THREE.LineSegments(g, new THREE.LineBasicMaterial({color: COLOURS[k]})));
    }
    return axes;
  }

  return {
    meshGeometry: meshGeometry,
    toolGeometry: toolGeometry,
    surfaceGeometry: surfaceGeometry,
    axesGroup: axesGroup
  };
})();

// scallop report viewer: a small WebGL 1 viewer written for scallop.
// Orbit (drag), pan (right-drag or shift-drag), zoom (wheel), fit-to-view,
// a section plane, colouring by move kind, achieved feed, zone or simulated
// deviation, and a slider that plays the toolpath over time.
"use strict";
(function () {
  var errorsEl = document.getElementById("errors");
  function report(msg) { errorsEl.textContent += msg + "\n"; }
  window.onerror = function (msg, src, line) { report("error: " + msg + (line ? " (line " + line + ")" : "")); return false; };
  window.addEventListener("unhandledrejection", function (e) { report("unhandled rejection: " + e.reason); });
  var consoleError = console.error;
  console.error = function () { report(Array.prototype.join.call(arguments, " ")); consoleError.apply(console, arguments); };

  function decode(text, Type) {
    if (!text) return null;
    var bin = atob(text), bytes = new Uint8Array(bin.length);
    for (var i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
    return new Type(bytes.buffer);
  }
  // The colour ramp of the PNG pictures: blue, cyan, green, yellow, red.
  var STOPS = [[40, 60, 200], [0, 190, 220], [40, 190, 60], [240, 220, 30], [220, 50, 40]];
  function ramp(t, out, k) {
    t = isFinite(t) ? Math.min(1, Math.max(0, t)) * 4 : 0;
    var i = Math.min(3, Math.floor(t)), f = t - i;
    for (var c = 0; c < 3; c++) out[k + c] = (STOPS[i][c] + (STOPS[i + 1][c] - STOPS[i][c]) * f) / 255;
  }
  // Deviation view: gouges, cells with no part under them, walls (not measured from above).
  var GOUGE = [230, 0, 230], NO_PART = [77, 77, 77], WALL = [205, 205, 190];
  // The engagement colouring's top: 1.5 x the target and above are red.
  var ENGAGEMENT_TOP = 1.5;
  function rgb(c) { return "vec3(" + c.map(function (v) { return (v / 255).toFixed(4); }).join(", ") + ")"; }
  var ZONE_COLOURS = [[31, 119, 180], [255, 127, 14], [44, 160, 44], [214, 39, 40], [148, 103, 189],
    [140, 86, 75], [227, 119, 194], [127, 127, 127], [188, 189, 34], [23, 190, 207]];

  // --- column-major 4x4 matrices -------------------------------------------
  function perspective(fovy, aspect, near, far) {
    var f = 1 / Math.tan(fovy / 2), nf = 1 / (near - far);
    return [f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) * nf, -1, 0, 0, 2 * far * near * nf, 0];
  }
  function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
  function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
  function norm(a) { var l = Math.hypot(a[0], a[1], a[2]) || 1; return [a[0] / l, a[1] / l, a[2] / l]; }
  function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  function lookAt(eye, target, up) {
    var z = norm(sub(eye, target)), x = norm(cross(up, z)), y = cross(z, x);
    return [x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0, -dot(x, eye), -dot(y, eye), -dot(z, eye), 1];
  }
  function mul(a, b) {
    var r = new Array(16);
    for (var i = 0; i < 4; i++) for (var j = 0; j < 4; j++) {
      var s = 0;
      for (var k = 0; k < 4; k++) s += a[k * 4 + j] * b[i * 4 + k];
      r[i * 4 + j] = s;
    }
    return r;
  }

  var data = JSON.parse(document.getElementById("scene-data").textContent);
  var canvas = document.getElementById("gl");
  var gl = null, drawn = false;
  var FOV = 35 * Math.PI / 180;
  var cam = { target: [0, 0, 0], dist: 1, yaw: -Math.PI / 4, pitch: 0.6 };
  var ui = {};
  ["fit", "colour", "showPart", "showStock", "showPath", "showRapids", "section", "sectionAxis", "sectionPos",
    "legend", "play", "time", "timeLabel", "pathNote"].forEach(function (id) { ui[id] = document.getElementById(id); });

  var VS_MESH = "attribute vec3 aPos; attribute vec3 aNormal; attribute vec3 aColour; uniform mat4 uMvp;" +
    "varying vec3 vPos; varying vec3 vNormal; varying vec3 vColour;" +
    "void main() { vPos = aPos; vNormal = aNormal; vColour = aColour; gl_Position = uMvp * vec4(aPos, 1.0); }";
  // Deviation colouring per fragment: the cell of the deviation map under the
  // fragment (a texture, nearest cell), so a large facet shows every cell it
  // covers; faces steeper than wallNormalZ take the wall colour (a height map
  // seen from above does not measure them), cells with no part the grey.
  var FS_MESH = "#ifdef GL_FRAGMENT_PRECISION_HIGH\nprecision highp float;\n#else\nprecision mediump float;\n#endif\n" +
    "uniform vec4 uPlane; uniform vec3 uLight; uniform float uDevMode; uniform vec4 uDevRect; uniform float uWallZ;" +
    "uniform sampler2D uDev; varying vec3 vPos; varying vec3 vNormal; varying vec3 vColour;" +
    "void main() { if (dot(uPlane.xyz, vPos) > uPlane.w) discard;" +
    " vec3 n = normalize(vNormal); vec3 c = vColour;" +
    " if (uDevMode > 0.5) {" +
    "  vec2 uv = (vPos.xy - uDevRect.xy) * uDevRect.zw;" +
    "  vec4 t = texture2D(uDev, clamp(uv, 0.0, 1.0));" +
    "  bool inside = uv.x >= 0.0 && uv.y >= 0.0 && uv.x <= 1.0 && uv.y <= 1.0 && t.a > 0.5;" +
    "  c = abs(n.z) < uWallZ ? " + rgb(WALL) + " : inside ? t.rgb : " + rgb(NO_PART) + "; }" +
    " float l = 0.3 + 0.7 * abs(dot(n, uLight)); gl_FragColor = vec4(c * l, 1.0); }";
  var VS_LINE = "attribute vec3 aPos; attribute vec3 aColour; attribute float aTime; uniform mat4 uMvp;" +
    "uniform float uPointSize; varying vec3 vPos; varying vec3 vColour; varying float vTime;" +
    "void main() { vPos = aPos; vColour = aColour; vTime = aTime; gl_PointSize = uPointSize;" +
    " gl_Position = uMvp * vec4(aPos, 1.0); }";
  var FS_LINE = "precision mediump float; uniform vec4 uPlane; uniform float uTime;" +
    "varying vec3 vPos; varying vec3 vColour; varying float vTime;" +
    "void main() { if (vTime > uTime || dot(uPlane.xyz, vPos) > uPlane.w) discard; gl_FragColor = vec4(vColour, 1.0); }";

  function shader(type, src) {
    var s = gl.createShader(type);
    gl.shaderSource(s, src);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error("shader: " + gl.getShaderInfoLog(s));
    return s;
  }
  function program(vs, fs) {
    var p = gl.createProgram();
    gl.attachShader(p, shader(gl.VERTEX_SHADER, vs));
    gl.attachShader(p, shader(gl.FRAGMENT_SHADER, fs));
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error("link: " + gl.getProgramInfoLog(p));
    p.u = {};
    ["uMvp", "uPlane", "uLight", "uTime", "uPointSize", "uDevMode", "uDevRect", "uWallZ", "uDev"].forEach(function (n) { p.u[n] = gl.getUniformLocation(p, n); });
    return p;
  }
  function buffer(array) {
    var b = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, b);
    gl.bufferData(gl.ARRAY_BUFFER, array, gl.STATIC_DRAW);
    return b;
  }
  var enabled = [];
  function attrib(prog, name, buf, size) {
    var loc = gl.getAttribLocation(prog, name);
    if (loc < 0) return;
    gl.bindBuffer(gl.ARRAY_BUFFER, buf);
    gl.enableVertexAttribArray(loc);
    gl.vertexAttribPointer(loc, size, gl.FLOAT, false, 0, 0);
    enabled.push(loc);
  }
  function release() { enabled.forEach(function (l) { gl.disableVertexAttribArray(l); }); enabled = []; }

  // --- scene ---------------------------------------------------------------
  var part = null, stock = null, path = null, marker = null, meshProg = null, lineProg = null;
  function buildPart() {
    if (!data.part) return;
    var pos = decode(data.part.positions, Float32Array), idx = decode(data.part.indices, Uint32Array);
    var n = idx.length, p = new Float32Array(3 * n), nn = new Float32Array(3 * n);
    for (var t = 0; t < n; t += 3) {
      var a = 3 * idx[t], b = 3 * idx[t + 1], c = 3 * idx[t + 2];
      var e1 = [pos[b] - pos[a], pos[b + 1] - pos[a + 1], pos[b + 2] - pos[a + 2]];
      var e2 = [pos[c] - pos[a], pos[c + 1] - pos[a + 1], pos[c + 2] - pos[a + 2]];
      var fn = norm(cross(e1, e2));
      for (var k = 0; k < 3; k++) {
        var v = 3 * idx[t + k];
        for (var d = 0; d < 3; d++) { p[3 * (t + k) + d] = pos[v + d]; nn[3 * (t + k) + d] = fn[d]; }
      }
    }
    var c = new Float32Array(3 * n);
    for (t = 0; t < 3 * n; t += 3) { c[t] = 0.67; c[t + 1] = 0.73; c[t + 2] = 0.8; }
    part = { count: n, pos: buffer(p), normal: buffer(nn), colour: buffer(c) };
  }
  // The deviation map as an RGBA texture (one texel per cell, alpha 0 where no part lies).
  var devTexture = null;
  function buildDeviation() {
    var d = data.deviation;
    if (!d || !part || d.nx < 1 || d.ny < 1) return;
    var limit = gl.getParameter(gl.MAX_TEXTURE_SIZE);
    if (d.nx > limit || d.ny > limit) { ui.pathNote.textContent += " (the deviation map is larger than this browser's textures)"; return; }
    var v = decode(d.values, Float32Array), px = new Uint8Array(4 * d.nx * d.ny), c = [0, 0, 0];
    for (var i = 0; i < v.length; i++) {
      if (!isFinite(v[i])) continue;
      if (v[i] < -d.gougeTolerance) c = GOUGE.map(function (x) { return x / 255; });
      else ramp(d.max > 0 ? Math.max(0, v[i]) / d.max : 0, c, 0);
      for (var k = 0; k < 3; k++) px[4 * i + k] = Math.round(255 * c[k]);
      px[4 * i + 3] = 255;
    }
    devTexture = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, devTexture);
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, d.nx, d.ny, 0, gl.RGBA, gl.UNSIGNED_BYTE, px);
    [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER].forEach(function (f) { gl.texParameteri(gl.TEXTURE_2D, f, gl.NEAREST); });
    [gl.TEXTURE_WRAP_S, gl.TEXTURE_WRAP_T].forEach(function (w) { gl.texParameteri(gl.TEXTURE_2D, w, gl.CLAMP_TO_EDGE); });
    devTexture.rect = [d.origin[0] - 0.5 * d.cell[0], d.origin[1] - 0.5 * d.cell[1], 1 / (d.cell[0] * d.nx), 1 / (d.cell[1] * d.ny)];
  }
  function buildStock() {
    if (!data.stock) return;
    var lo = data.stock.min, hi = data.stock.max, p = [], corner = function (k) {
      return [k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]];
    };
    for (var a = 0; a < 8; a++) [1, 2, 4].forEach(function (bit) {
      if (!(a & bit)) p.push.apply(p, corner(a).concat(corner(a | bit)));
    });
    var n = p.length / 3, c = new Float32Array(3 * n), t = new Float32Array(n);
    for (var i = 0; i < 3 * n; i++) c[i] = 0.55;
    for (i = 0; i < n; i++) t[i] = -1;
    stock = { count: n, pos: buffer(new Float32Array(p)), colour: buffer(c), time: buffer(t) };
  }
  function buildPath() {
    if (!data.path || data.path.shown < 2) return;
    var d = data.path;
    path = {
      count: d.shown, posArray: decode(d.positions, Float32Array), kinds: decode(d.kinds, Uint8Array),
      times: decode(d.times, Float32Array), feeds: decode(d.feeds, Float32Array), zones: decode(d.zones, Uint16Array),
      engagement: decode(d.engagement, Float32Array)
    };
    path.pos = buffer(path.posArray);
    path.time = buffer(path.times);
    path.colour = gl.createBuffer();
    marker = { pos: gl.createBuffer(), colour: buffer(new Float32Array([0, 0, 0])), time: buffer(new Float32Array([-1])) };
    ui.pathNote.textContent = d.shown < d.moves
      ? "toolpath: " + d.moves + " moves, " + d.shown + " shown in 3D (decimated for display; figures and plots use every move)"
      : "toolpath: " + d.moves + " moves";
  }

  // --- colours ---------------------------------------------------------------
  function swatch(rgb, label) {
    return "<span><span class=\"sw\" style=\"background:rgb(" + rgb.join(",") + ")\"></span>" + label + "</span>";
  }
  function colourise() {
    var mode = ui.colour.value, legend = "", i, k;
    if (path) {
      var pc = new Float32Array(3 * path.count), maxFeed = data.path.maxFeed || 1;
      for (i = 0; i < path.count; i++) {
        var kind = path.kinds[i], rgb;
        if (mode === "feed" && path.feeds && (kind === 2 || kind === 3)) { ramp(path.feeds[i] / maxFeed, pc, 3 * i); continue; }
        if (mode === "engagement" && path.engagement && path.engagement[i] >= 0) {
          ramp(Math.min(path.engagement[i], ENGAGEMENT_TOP) / ENGAGEMENT_TOP, pc, 3 * i); continue;
        }
        if (mode === "zone" && path.zones) rgb = ZONE_COLOURS[path.zones[i] % ZONE_COLOURS.length];
        else if (mode === "kind") rgb = data.kindColours[kind];
        else rgb = kind === 2 || kind === 3 ? [60, 60, 60] : [190, 190, 190];
        for (k = 0; k < 3; k++) pc[3 * i + k] = rgb[k] / 255;
      }
      gl.bindBuffer(gl.ARRAY_BUFFER, path.colour);
      gl.bufferData(gl.ARRAY_BUFFER, pc, gl.STATIC_DRAW);
    }
    if (mode === "kind") legend = data.kindNames.map(function (n, j) { return swatch(data.kindColours[j], n); }).join("");
    if (mode === "feed") legend = "<span>achieved feed (look-ahead): 0 <span class=\"ramp\"></span> " +
      Math.round(data.path.maxFeed) + " mm/min</span>";
    if (mode === "engagement") legend = "<span>simulated engagement / target: 0 <span class=\"ramp\"></span> " +
      ENGAGEMENT_TOP + " and above (1 = the target; grey: not measured)</span>";
    if (mode === "zone") legend = (data.zoneNames || []).map(function (n, j) { return swatch(ZONE_COLOURS[j % ZONE_COLOURS.length], n); }).join("");
    if (mode === "deviation") legend = "<span>material left: 0 <span class=\"ramp\"></span> " + data.deviation.max.toFixed(4) +
      " mm</span>" + swatch(GOUGE, "gouge (below -" + data.deviation.gougeTolerance.toFixed(4) + " mm)") + swatch(NO_PART, "no part") +
      swatch(WALL, "wall (steeper than " + Math.round(Math.acos(data.deviation.wallNormalZ) * 180 / Math.PI) + "°: not measured from above)");
    ui.legend.innerHTML = legend;
  }
  function colourModes() {
    var modes = [["kind", "move type"]];
    if (data.path && data.path.feeds) modes.push(["feed", "achieved feed"]);
    if (data.path && data.path.zones) modes.push(["zone", data.zoneLabel || "zone"]);
    if (data.path && data.path.engagement) modes.push(["engagement", "simulated engagement"]);
    if (devTexture) modes.push(["deviation", "simulated deviation"]);
    ui.colour.innerHTML = modes.map(function (m) { return "<option value=\"" + m[0] + "\">" + m[1] + "</option>"; }).join("");
  }

  // --- view ------------------------------------------------------------------
  function fit() { cam.target = [0, 0, 0]; cam.dist = 1.02 * data.radius / Math.sin(FOV / 2); draw(); }
  function eye() {
    var cp = Math.cos(cam.pitch);
    return [cam.target[0] + cam.dist * cp * Math.cos(cam.yaw), cam.target[1] + cam.dist * cp * Math.sin(cam.yaw),
      cam.target[2] + cam.dist * Math.sin(cam.pitch)];
  }
  var playing = false, time = Infinity;
  function currentTime() {
    if (!data.path) return Infinity;
    var v = +ui.time.value;
    return v >= 1000 ? Infinity : data.path.totalTime * v / 1000;
  }
  function markerAt(t) {
    // The shown vertex reached last at time t (binary search), then linear between it and the next.
    var times = path.times, lo = 0, hi = path.count - 1;
    if (!(t < times[hi])) return null;
    while (hi - lo > 1) { var mid = (lo + hi) >> 1; if (times[mid] <= t) lo = mid; else hi = mid; }
    var f = times[hi] > times[lo] ? (t - times[lo]) / (times[hi] - times[lo]) : 0, p = path.posArray;
    return [p[3 * lo] + f * (p[3 * hi] - p[3 * lo]), p[3 * lo + 1] + f * (p[3 * hi + 1] - p[3 * lo + 1]),
      p[3 * lo + 2] + f * (p[3 * hi + 2] - p[3 * lo + 2])];
  }
  function plane() {
    if (!ui.section.checked) return [0, 0, 0, 1];
    var axis = { x: 0, y: 1, z: 2 }[ui.sectionAxis.value], n = [0, 0, 0], r = data.radius;
    n[axis] = 1;
    return [n[0], n[1], n[2], -r + 2 * r * (+ui.sectionPos.value) / 1000];
  }
  function draw() {
    if (!gl) return;
    try {
      var w = canvas.clientWidth, h = canvas.clientHeight, dpr = window.devicePixelRatio || 1;
      if (canvas.width !== Math.round(w * dpr) || canvas.height !== Math.round(h * dpr)) {
        canvas.width = Math.round(w * dpr); canvas.height = Math.round(h * dpr);
      }
      gl.viewport(0, 0, canvas.width, canvas.height);
      gl.clearColor(0.957, 0.961, 0.969, 1);
      gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
      var e = eye(), r = data.radius;
      var proj = perspective(FOV, canvas.width / Math.max(1, canvas.height), Math.max(cam.dist - 3 * r, cam.dist * 0.01), cam.dist + 3 * r);
      var mvp = mul(proj, lookAt(e, cam.target, [0, 0, 1]));
      var pl = plane(), light = norm(sub(e, cam.target));
      time = currentTime();
      if (part && ui.showPart.checked) {
        gl.useProgram(meshProg);
        gl.uniformMatrix4fv(meshProg.u.uMvp, false, mvp);
        gl.uniform4fv(meshProg.u.uPlane, pl);
        gl.uniform3fv(meshProg.u.uLight, light);
        var dev = devTexture && ui.colour.value === "deviation";
        gl.uniform1f(meshProg.u.uDevMode, dev ? 1 : 0);
        if (dev) {
          gl.activeTexture(gl.TEXTURE0);
          gl.bindTexture(gl.TEXTURE_2D, devTexture);
          gl.uniform1i(meshProg.u.uDev, 0);
          gl.uniform4fv(meshProg.u.uDevRect, devTexture.rect);
          gl.uniform1f(meshProg.u.uWallZ, data.deviation.wallNormalZ);
        }
        attrib(meshProg, "aPos", part.pos, 3); attrib(meshProg, "aNormal", part.normal, 3); attrib(meshProg, "aColour", part.colour, 3);
        gl.enable(gl.POLYGON_OFFSET_FILL); gl.polygonOffset(1, 1);
        gl.drawArrays(gl.TRIANGLES, 0, part.count);
        gl.disable(gl.POLYGON_OFFSET_FILL);
        release();
      }
      gl.useProgram(lineProg);
      gl.uniformMatrix4fv(lineProg.u.uMvp, false, mvp);
      gl.uniform4fv(lineProg.u.uPlane, pl);
      gl.uniform1f(lineProg.u.uTime, time === Infinity ? 3.0e38 : time);
      gl.uniform1f(lineProg.u.uPointSize, 9.0);
      if (stock && ui.showStock.checked) {
        attrib(lineProg, "aPos", stock.pos, 3); attrib(lineProg, "aColour", stock.colour, 3); attrib(lineProg, "aTime", stock.time, 1);
        gl.drawArrays(gl.LINES, 0, stock.count);
        release();
      }
      if (path && ui.showPath.checked) {
        attrib(lineProg, "aPos", path.pos, 3); attrib(lineProg, "aColour", path.colour, 3); attrib(lineProg, "aTime", path.time, 1);
        if (ui.showRapids.checked) gl.drawArrays(gl.LINE_STRIP, 0, path.count);
        else drawWithoutRapids();
        release();
        var m = time === Infinity ? null : markerAt(time);
        if (m) {
          gl.bindBuffer(gl.ARRAY_BUFFER, marker.pos);
          gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(m), gl.DYNAMIC_DRAW);
          attrib(lineProg, "aPos", marker.pos, 3); attrib(lineProg, "aColour", marker.colour, 3); attrib(lineProg, "aTime", marker.time, 1);
          gl.drawArrays(gl.POINTS, 0, 1);
          release();
        }
      }
      if (data.path) {
        var shown = time === Infinity ? data.path.totalTime : time;
        ui.timeLabel.textContent = "t = " + shown.toFixed(1) + " s of " + data.path.totalTime.toFixed(1) + " s";
      }
      var err = gl.getError();
      if (err !== gl.NO_ERROR) throw new Error("WebGL error " + err);
      if (!drawn) { drawn = true; document.body.dataset.drawn = "1"; }
    } catch (ex) {
      report("draw: " + (ex && ex.message ? ex.message : ex));
    }
  }
  // Runs of cutting moves (feed, link, plunge) as separate strips: rapids and retracts hidden.
  var runs = null;
  function drawWithoutRapids() {
    if (!runs) {
      runs = [];
      var start = -1;
      for (var i = 1; i < path.count; i++) {
        var cut = path.kinds[i] === 1 || path.kinds[i] === 2 || path.kinds[i] === 3;
        if (cut && start < 0) start = i - 1;
        if (!cut && start >= 0) { runs.push([start, i - start]); start = -1; }
      }
      if (start >= 0) runs.push([start, path.count - start]);
    }
    runs.forEach(function (r) { gl.drawArrays(gl.LINE_STRIP, r[0], r[1]); });
  }

  function controls() {
    var drag = null;
    canvas.addEventListener("contextmenu", function (e) { e.preventDefault(); });
    canvas.addEventListener("mousedown", function (e) { drag = { x: e.clientX, y: e.clientY, pan: e.button === 2 || e.shiftKey }; });
    window.addEventListener("mouseup", function () { drag = null; });
    window.addEventListener("mousemove", function (e) {
      if (!drag) return;
      var dx = e.clientX - drag.x, dy = e.clientY - drag.y;
      drag.x = e.clientX; drag.y = e.clientY;
      if (drag.pan) {
        var z = norm(sub(eye(), cam.target)), x = norm(cross([0, 0, 1], z)), y = cross(z, x);
        var s = 2 * cam.dist * Math.tan(FOV / 2) / Math.max(1, canvas.clientHeight);
        for (var k = 0; k < 3; k++) cam.target[k] += (-dx * x[k] + dy * y[k]) * s;
      } else {
        cam.yaw -= dx * 0.01;
        cam.pitch = Math.max(-1.55, Math.min(1.55, cam.pitch + dy * 0.01));
      }
      draw();
    });
    canvas.addEventListener("wheel", function (e) { e.preventDefault(); cam.dist *= Math.exp(e.deltaY * 0.001); draw(); }, { passive: false });
    ui.fit.addEventListener("click", fit);
    ui.colour.addEventListener("change", function () { colourise(); draw(); });
    ["showPart", "showStock", "showPath", "showRapids", "section", "sectionAxis"].forEach(function (id) { ui[id].addEventListener("change", draw); });
    ui.sectionPos.addEventListener("input", draw);
    ui.time.addEventListener("input", draw);
    window.addEventListener("resize", draw);
    var last = 0, PLAY_SECONDS = 30;
    function step(now) {
      if (!playing) return;
      var dt = last ? (now - last) / 1000 : 0;
      last = now;
      var v = Math.min(1000, +ui.time.value + dt * 1000 / PLAY_SECONDS);
      ui.time.value = v;
      draw();
      if (v >= 1000) { playing = false; ui.play.textContent = "play"; } else requestAnimationFrame(step);
    }
    ui.play.addEventListener("click", function () {
      playing = !playing;
      ui.play.textContent = playing ? "pause" : "play";
      if (playing) { if (+ui.time.value >= 1000) ui.time.value = 0; last = 0; requestAnimationFrame(step); }
    });
  }

  try {
    if (!data) throw new Error("the report has no scene");
    gl = canvas.getContext("webgl", { preserveDrawingBuffer: true, antialias: true }) ||
      canvas.getContext("experimental-webgl", { preserveDrawingBuffer: true });
    if (!gl) throw new Error("WebGL is not available in this browser");
    if (!gl.getExtension("OES_element_index_uint")) { /* indices are expanded on the CPU: not needed */ }
    meshProg = program(VS_MESH, FS_MESH);
    lineProg = program(VS_LINE, FS_LINE);
    gl.enable(gl.DEPTH_TEST);
    buildPart(); buildStock(); buildPath(); buildDeviation();
    if (!data.path) document.getElementById("player").style.display = "none";
    colourModes();
    // report.html#colour=feed opens with that colouring (for links and screenshots).
    var asked = /colour=(\w+)/.exec(window.location.hash);
    if (asked && ui.colour.querySelector("option[value=\"" + asked[1] + "\"]")) ui.colour.value = asked[1];
    // ...and report.html#hide=path,stock starts with those layers hidden.
    var hide = /hide=([\w,]+)/.exec(window.location.hash), layers = { part: "showPart", stock: "showStock", path: "showPath", rapids: "showRapids" };
    if (hide) hide[1].split(",").forEach(function (h) { if (layers[h]) ui[layers[h]].checked = false; });
    colourise(); controls(); fit();
  } catch (ex) {
    report("viewer: " + (ex && ex.message ? ex.message : ex));
  }
})();

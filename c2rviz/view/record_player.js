/* c2rviz's player for a recorded page (NAME.html); c2rviz/view/record_page.py writes it in.
 *
 * The page holds viser's client with a static scene (the robot, marker and object nodes)
 * and, in <script> elements, the recording: its description (JSON: joints, the chain's
 * kinematics from Pinocchio, the nodes, what was wrong) and its frames, marker changes and
 * times, gzipped and in base64. This player poses the arm for the time shown with the
 * chain's forward kinematics, poses the parts (NAME.csv's part columns, in the base frame),
 * shows the markers and objects there were at that time
 * (backwards too: each is computed from the time alone), and draws a readout and plots
 * that end at the time shown, with a cursor there. It drives the scene through viser's
 * own message queue (window.__viserMutable, which viser's client sets up for tests): the
 * messages are viser's wire format (SetPositionMessage, ...).
 *
 * window.__c2rvizPlayer is the player's handle (tests and the curious): state(), seek(t),
 * step(n), play(), pause(), setSpeed(x), setWindow(s).
 */
(function () {
  "use strict";

  var SPEEDS = [0.25, 0.5, 1, 2, 4];
  var WINDOW_RANGE = [5, 120];
  var COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2",
    "#17becf"];
  var MAX_MARKERS = 1000;
  var PLOT_POINTS = 400;
  var VISER_WAIT_MS = 120000;

  var meta = JSON.parse(document.getElementById("c2rviz-recording").textContent);
  var n = meta.joints.length;
  var parts = meta.parts || [];
  var width = n + 6 + 6 * parts.length;
  var data = { times: new Float64Array(0), values: new Float32Array(0), marks: new Float64Array(0) };
  var lastClear = new Int32Array(0);
  var st = {
    ready: false, time: 0, frame: -1, playing: false, speed: 1, window: 20,
    chosen: meta.joints.map(function () { return true; }),
    problems: meta.problems.slice(), drawnFrame: -2, drawnMarks: -1, drawnObjects: -1,
    markersShown: 0, objectsShown: [], plotCursor: null, plotRange: null, plotDraws: 0,
    refused: 0, lastTick: null
  };
  var objectVisible = meta.objectNodes.map(function () { return false; });
  var partVisible = parts.map(function () { return null; });

  // ---------- small helpers

  function el(tag, attrs, children) {
    var node = document.createElement(tag);
    Object.keys(attrs || {}).forEach(function (key) {
      if (key === "text") node.textContent = attrs[key];
      else if (key.slice(0, 2) === "on") node.addEventListener(key.slice(2), attrs[key]);
      else node.setAttribute(key, attrs[key]);
    });
    (children || []).forEach(function (child) { node.appendChild(child); });
    return node;
  }

  function search(sorted, value) {  // how many entries are <= value
    var lo = 0, hi = sorted.length;
    while (lo < hi) {
      var mid = (lo + hi) >> 1;
      if (sorted[mid] <= value) lo = mid + 1; else hi = mid;
    }
    return lo;
  }

  function scale(j) { return meta.joints[j].prismatic ? 1 : 180 / Math.PI; }
  function unit(j) { return meta.joints[j].prismatic ? "m" : "\u00b0"; }
  function fmt(v, digits) { return (Math.round(v * Math.pow(10, digits)) / Math.pow(10, digits)).toFixed(digits); }

  // ---------- the chain's forward kinematics (record_frames.py's numbers)

  function qmul(a, b) {
    return [a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
      a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
      a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
      a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]];
  }
  function cross(a, b) {
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  }
  function qrot(q, v) {  // rotate v by the unit quaternion q (w, x, y, z)
    var u = [q[1], q[2], q[3]], t = cross(u, v);
    t = [2 * t[0], 2 * t[1], 2 * t[2]];
    var c = cross(u, t);
    return [v[0] + q[0] * t[0] + c[0], v[1] + q[0] * t[1] + c[1], v[2] + q[0] * t[2] + c[2]];
  }
  function compose(a, b) {
    var r = qrot(a.q, b.p);
    return { p: [a.p[0] + r[0], a.p[1] + r[1], a.p[2] + r[2]], q: qmul(a.q, b.q) };
  }
  function relative(a, b) {  // b in a's frame: a^-1 * b
    var c = [a.q[0], -a.q[1], -a.q[2], -a.q[3]];
    return { p: qrot(c, [b.p[0] - a.p[0], b.p[1] - a.p[1], b.p[2] - a.p[2]]), q: qmul(c, b.q) };
  }
  function rpyQuat(roll, pitch, yaw) {  // Rz(yaw) Ry(pitch) Rx(roll), as Pinocchio's rpy
    var h = function (a, i) { var q = [Math.cos(a / 2), 0, 0, 0]; q[i] = Math.sin(a / 2); return q; };
    return qmul(qmul(h(yaw, 3), h(pitch, 2)), h(roll, 1));
  }
  var base = meta.base ? placement(meta.base) : { p: [0, 0, 0], q: [1, 0, 0, 0] };
  function placement(x) { return { p: [x[0], x[1], x[2]], q: [x[3], x[4], x[5], x[6]] }; }
  function exp6(tw, s) {  // exp of the twist tw = (v, w) times s
    var v = [tw[0] * s, tw[1] * s, tw[2] * s], w = [tw[3] * s, tw[4] * s, tw[5] * s];
    var th = Math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    if (th < 1e-12) return { p: v, q: [1, 0, 0, 0] };
    var k = [w[0] / th, w[1] / th, w[2] / th], h = Math.sin(th / 2);
    var kv = cross(k, v), kkv = cross(k, kv);
    var a = (1 - Math.cos(th)) / th, b = (th - Math.sin(th)) / th;
    return {
      p: [v[0] + a * kv[0] + b * kkv[0], v[1] + a * kv[1] + b * kkv[1], v[2] + a * kv[2] + b * kkv[2]],
      q: [Math.cos(th / 2), k[0] * h, k[1] * h, k[2] * h]
    };
  }
  var kin = meta.kinematics;
  var jointPlacements = kin.joints.map(function (j) { return placement(j.placement); });
  var linkPlacements = kin.links.map(function (l) { return placement(l.placement); });
  function poseLinks(q) {
    var poses = [{ p: [0, 0, 0], q: [1, 0, 0, 0] }];
    kin.joints.forEach(function (j, i) {
      var local = jointPlacements[i];
      if (j.chain >= 0) local = compose(local, exp6(j.twist, q[j.chain] - j.home));
      poses.push(compose(poses[j.parent], local));
    });
    return kin.links.map(function (l, i) { return compose(poses[l.joint], linkPlacements[i]); });
  }

  // ---------- viser's scene

  function viser() { return window.__viserMutable; }
  function send(messages) {
    var m = viser();
    if (!m || !messages.length) return;
    for (var i = 0; i < messages.length; i++) m.messageQueue.push(messages[i]);
    m.requestRender();
  }
  function sceneReady() {
    var tree = window.__viserSceneTree;
    if (!viser() || !tree) return false;
    var nodes = tree.getState();
    return meta.linkNodes.every(function (name) { return nodes[name] !== undefined; });
  }

  // ---------- the page around the scene

  var ui = {};
  function buildUi() {
    ui.problems = el("div", { id: "c2rviz-problems" });
    ui.back = el("button", { text: "\u25c0", title: "a frame back (\u2190)", onclick: function () { step(-1); } });
    ui.play = el("button", { text: "play", title: "play or pause (space)", onclick: function () { st.playing ? pause() : play(); } });
    ui.forward = el("button", { text: "\u25b6", title: "a frame on (\u2192)", onclick: function () { step(1); } });
    ui.slider = el("input", { type: "range", min: "0", max: String(meta.endS || 0), step: "0.001", value: "0", "aria-label": "time" });
    ui.slider.addEventListener("input", function () { seek(parseFloat(ui.slider.value)); });
    ui.timeInput = el("input", { type: "text", inputmode: "decimal", "aria-label": "time shown [s]", size: "8" });
    ui.timeInput.addEventListener("change", function () { typedTime(ui.timeInput.value); });
    ui.end = el("span", { text: "/ " + fmt(meta.endS || 0, 3) + " s" });
    ui.speed = el("select", { "aria-label": "speed", title: "speed" });
    SPEEDS.forEach(function (s) { ui.speed.appendChild(el("option", { value: String(s), text: s + "x" })); });
    ui.speed.value = "1";
    ui.speed.addEventListener("change", function () { setSpeed(parseFloat(ui.speed.value)); });
    ui.note = el("span", { id: "c2rviz-note" });
    ui.bar = el("div", { id: "c2rviz-bar" }, [ui.back, ui.play, ui.forward, ui.slider, ui.timeInput, ui.end, ui.speed, ui.note]);

    ui.readout = el("table", { id: "c2rviz-readout" });
    ui.windowInput = el("input", { type: "number", min: String(WINDOW_RANGE[0]), max: String(WINDOW_RANGE[1]), step: "1", value: String(st.window), "aria-label": "plot window [s]" });
    ui.windowInput.addEventListener("change", function () { setWindow(parseFloat(ui.windowInput.value)); });
    var boxes = meta.joints.map(function (joint, j) {
      var box = el("input", { type: "checkbox", checked: "checked", "aria-label": "plot " + joint.name });
      box.addEventListener("change", function () { st.chosen[j] = box.checked; redraw(); });
      return el("label", { style: "color:" + COLORS[j % COLORS.length] }, [box, document.createTextNode(joint.name)]);
    });
    ui.plots = [
      plot("joints [deg/m]"), plot("velocities [deg/s, m/s]"), plot("tool point speed [m/s]")
    ];
    ui.side = el("div", { id: "c2rviz-side" }, [
      el("div", { class: "c2rviz-title", text: meta.name + " \u2014 " + meta.robot }),
      ui.readout,
      el("div", { class: "c2rviz-row" }, [el("span", { text: "plot window s" }), ui.windowInput]),
      el("div", { class: "c2rviz-joints" }, boxes)
    ].concat(ui.plots.map(function (p) { return p.box; })));
    document.body.appendChild(ui.problems);
    document.body.appendChild(ui.side);
    document.body.appendChild(ui.bar);
    showProblems();
    document.addEventListener("keydown", function (event) {
      var tag = (event.target && event.target.tagName) || "";
      if (tag === "INPUT" || tag === "SELECT" || tag === "TEXTAREA") return;
      if (event.code === "Space") { st.playing ? pause() : play(); event.preventDefault(); }
      else if (event.code === "ArrowLeft") step(-1);
      else if (event.code === "ArrowRight") step(1);
    }, true);
  }

  function showProblems() {
    ui.problems.textContent = "";
    st.problems.forEach(function (text) { ui.problems.appendChild(el("div", { text: text })); });
    ui.problems.style.display = st.problems.length ? "block" : "none";
  }
  function problem(text) {
    if (st.problems.indexOf(text) < 0) st.problems.push(text);
    showProblems();
  }
  var noteTimer = null;
  function refuse(text) {  // a value out of range: say so, show the true value again
    st.refused += 1;
    ui.note.textContent = text;
    clearTimeout(noteTimer);
    noteTimer = setTimeout(function () { ui.note.textContent = ""; }, 4000);
    showTime();
    ui.windowInput.value = String(st.window);
    ui.speed.value = String(st.speed);
  }

  // ---------- controls

  function seek(t) {
    if (!isFinite(t) || t < 0 || t > meta.endS + 1e-9) {
      refuse("time " + t + " is not within 0.." + fmt(meta.endS, 3) + " s");
      return false;
    }
    st.time = t;
    redraw();
    return true;
  }
  function typedTime(text) {
    var t = Number(String(text).trim());
    if (String(text).trim() === "" || !isFinite(t)) { refuse("time " + JSON.stringify(text) + " is not a number of seconds"); return; }
    if (seek(t)) pause();
  }
  function step(frames) {
    pause();
    var times = data.times;
    if (!times.length) return;
    var k = Math.max(search(times, st.time + 1e-9) - 1, 0);
    if (frames < 0 && times[k] < st.time - 1e-9) k += 1;  // between frames: "back" is to this one
    k = Math.min(Math.max(k + frames, 0), times.length - 1);
    st.time = times[k];
    redraw();
  }
  function play() {
    if (st.time >= meta.endS) st.time = 0;
    st.playing = true;
    st.lastTick = null;
    ui.play.textContent = "pause";
  }
  function pause() {
    st.playing = false;
    ui.play.textContent = "play";
  }
  function setSpeed(x) {
    if (SPEEDS.indexOf(x) < 0) { refuse("speed " + x + " is not one of " + SPEEDS.join(", ")); return false; }
    st.speed = x;
    ui.speed.value = String(x);
    return true;
  }
  function setWindow(s) {
    if (!isFinite(s) || s < WINDOW_RANGE[0] || s > WINDOW_RANGE[1]) {
      refuse("plot window " + s + " s is not within " + WINDOW_RANGE[0] + ".." + WINDOW_RANGE[1] + " s");
      return false;
    }
    st.window = s;
    ui.windowInput.value = String(s);
    redraw();
    return true;
  }

  // ---------- drawing the time shown

  function frameAt(t) { return Math.max(search(data.times, t) - 1, 0); }
  function showTime() {
    ui.timeInput.value = fmt(st.time, 3);
    ui.slider.value = String(st.time);
  }

  function redraw() {
    st.drawnFrame = -2;
    st.drawnMarks = -1;
    st.drawnObjects = -1;
    draw();
  }

  function draw() {
    showTime();
    if (!st.ready) return;
    var messages = [];
    if (data.times.length) {
      var k = frameAt(st.time);
      st.frame = k;
      if (k !== st.drawnFrame) {
        st.drawnFrame = k;
        var q = Array.prototype.slice.call(data.values.subarray(k * width, k * width + n));
        var poses = poseLinks(q);  // in the root's frame; a link's node nests in its parent's
        poses.forEach(function (inRoot, i) {
          var name = meta.linkNodes[i], up = meta.linkParents[i];
          var pose = up < 0 ? inRoot : relative(poses[up], inRoot);
          messages.push({ type: "SetPositionMessage", name: name, position: pose.p, owner: "" });
          messages.push({ type: "SetOrientationMessage", name: name, wxyz: pose.q, owner: "" });
        });
        drawParts(k, messages);
        readout(k);
      }
    }
    drawMarkers(messages);
    drawObjects(messages);
    send(messages);
    drawPlots();
  }

  function drawMarkers(messages) {
    var marks = data.marks, count = marks.length / 13;
    var upto = search(markTimes, st.time);
    if (upto === st.drawnMarks) return;
    st.drawnMarks = upto;
    var from = upto ? Math.max(lastClear[upto - 1] + 1, upto - MAX_MARKERS, 0) : 0;
    var byShape = {};
    for (var i = from; i < upto && i < count; i++) {
      if (marks[i * 13 + 1] !== 0) continue;
      var shape = meta.shapes[marks[i * 13 + 12]];
      (byShape[shape] = byShape[shape] || []).push(i);
    }
    var shown = 0;
    Object.keys(meta.markerNodes).forEach(function (shape) {
      var rows = byShape[shape] || [];
      var positions = new Float32Array(rows.length * 3), wxyzs = new Float32Array(rows.length * 4);
      var colors = new Uint8Array(rows.length * 3);
      rows.forEach(function (row, j) {
        var o = row * 13;
        positions.set([marks[o + 2], marks[o + 3], marks[o + 4]], j * 3);
        wxyzs.set([marks[o + 5], marks[o + 6], marks[o + 7], marks[o + 8]], j * 4);
        colors.set([Math.round(marks[o + 9] * 255), Math.round(marks[o + 10] * 255), Math.round(marks[o + 11] * 255)], j * 3);
      });
      shown += rows.length;
      var node = meta.markerNodes[shape];
      messages.push({ type: "SceneNodeUpdateMessage", name: node, owner: "",
        updates: { batched_positions: positions, batched_wxyzs: wxyzs, batched_colors: colors } });
      messages.push({ type: "SetSceneNodeVisibilityMessage", name: node, visible: rows.length > 0, owner: "" });
    });
    st.markersShown = shown;
  }

  function partPose(k, i) {  // part i's pose in frame k (base frame), or null: not there
    var o = k * width + parts[i].column, x = Array.prototype.slice.call(data.values.subarray(o, o + 6));
    return x.every(isFinite) ? x : null;
  }
  function drawParts(k, messages) {
    parts.forEach(function (part, i) {
      if (!part.node) return;
      var x = partPose(k, i), on = x !== null;
      if (on) {
        var pose = compose(base, { p: [x[0], x[1], x[2]], q: rpyQuat(x[3], x[4], x[5]) });
        messages.push({ type: "SetPositionMessage", name: part.node, position: pose.p, owner: "" });
        messages.push({ type: "SetOrientationMessage", name: part.node, wxyz: pose.q, owner: "" });
      }
      if (on !== partVisible[i]) {
        partVisible[i] = on;
        messages.push({ type: "SetSceneNodeVisibilityMessage", name: part.node, visible: on, owner: "" });
      }
    });
  }

  function drawObjects(messages) {
    var changes = meta.objectChanges;
    var upto = search(objectTimes, st.time);
    if (upto === st.drawnObjects) return;
    st.drawnObjects = upto;
    var visible = upto ? changes[upto - 1][1] : [];
    st.objectsShown = visible.slice();
    meta.objectNodes.forEach(function (node, i) {
      var on = visible.indexOf(i) >= 0;
      if (on !== objectVisible[i]) {
        objectVisible[i] = on;
        messages.push({ type: "SetSceneNodeVisibilityMessage", name: node, visible: on, owner: "" });
      }
    });
  }

  function readout(k) {
    var v = data.values, o = k * width, rows = [];
    rows.push(["time", fmt(st.time, 3) + " s (frame " + (k + 1) + " of " + data.times.length + ")"]);
    meta.joints.forEach(function (joint, j) {
      rows.push([joint.name, fmt(v[o + j] * scale(j), joint.prismatic ? 4 : 2) + " " + unit(j)]);
    });
    rows.push(["tool xyz", [0, 1, 2].map(function (i) { return fmt(v[o + n + i], 4); }).join(" ") + " m"]);
    rows.push(["tool rpy", [3, 4, 5].map(function (i) { return fmt(v[o + n + i] * 180 / Math.PI, 2); }).join(" ") + "\u00b0"]);
    ui.readout.textContent = "";
    rows.forEach(function (row) {
      ui.readout.appendChild(el("tr", {}, [el("td", { text: row[0] }), el("td", { text: row[1] })]));
    });
  }

  // ---------- plots: the window up to the time shown, a cursor there

  function plot(title) {
    var canvas = el("canvas", { width: "320", height: "150" });
    return { canvas: canvas, box: el("div", { class: "c2rviz-plot" }, [el("div", { text: title }), canvas]) };
  }

  function drawPlots() {
    var times = data.times;
    if (!times.length) return;
    var x0 = Math.min(Math.max(st.time - st.window * 0.75, 0), Math.max(meta.endS - st.window, 0));
    var x1 = x0 + st.window;  // the cursor stays in view; the window stays in the recording
    var k0 = Math.max(search(times, x0) - 1, 0), k1 = Math.min(search(times, x1), times.length);
    var stride = Math.max(1, Math.ceil((k1 - k0) / PLOT_POINTS));
    var idx = [];
    for (var k = k0; k < k1; k += stride) idx.push(k);
    if (idx.length && idx[idx.length - 1] !== k1 - 1) idx.push(k1 - 1);
    var v = data.values;
    var position = [], velocity = [], speed = [];
    meta.joints.forEach(function (joint, j) {
      if (!st.chosen[j]) return;
      var color = COLORS[j % COLORS.length], s = scale(j);
      position.push({ color: color, ys: idx.map(function (i) { return v[i * width + j] * s; }) });
      if (!joint.continuous) {
        position.push({ color: color, dash: true, ys: idx.map(function () { return joint.lower * s; }) });
        position.push({ color: color, dash: true, ys: idx.map(function () { return joint.upper * s; }) });
      }
      velocity.push({ color: color, ys: idx.map(function (i) { return rate(i, j) * s; }) });
    });
    speed.push({ color: "#444", ys: idx.map(function (i) {
      var a = Math.max(i - 1, 0), dt = times[i] - times[a];
      if (dt <= 0) return 0;
      var dx = v[i * width + n] - v[a * width + n], dy = v[i * width + n + 1] - v[a * width + n + 1];
      var dz = v[i * width + n + 2] - v[a * width + n + 2];
      return Math.sqrt(dx * dx + dy * dy + dz * dz) / dt;
    }) });
    var xs = idx.map(function (i) { return times[i]; });
    [position, velocity, speed].forEach(function (series, p) { chart(ui.plots[p].canvas, xs, series, x0, x1); });
    st.plotCursor = st.time;
    st.plotRange = [x0, x1];
    st.plotDraws += 1;
  }

  function rate(i, j) {
    var a = Math.max(i - 1, 0), dt = data.times[i] - data.times[a];
    return dt > 0 ? (data.values[i * width + j] - data.values[a * width + j]) / dt : 0;
  }

  function chart(canvas, xs, series, x0, x1) {
    var ctx = canvas.getContext("2d"), w = canvas.width, h = canvas.height, left = 42, bottom = 18;
    ctx.clearRect(0, 0, w, h);
    var lo = Infinity, hi = -Infinity;
    series.forEach(function (s) { s.ys.forEach(function (y) { if (y < lo) lo = y; if (y > hi) hi = y; }); });
    if (!isFinite(lo)) { lo = -1; hi = 1; }
    if (hi - lo < 1e-9) { lo -= 1; hi += 1; }
    var pad = (hi - lo) * 0.05;
    lo -= pad; hi += pad;
    var X = function (x) { return left + (x - x0) / (x1 - x0) * (w - left - 4); };
    var Y = function (y) { return 4 + (hi - y) / (hi - lo) * (h - bottom - 8); };
    ctx.strokeStyle = "#ddd"; ctx.fillStyle = "#666"; ctx.font = "10px sans-serif"; ctx.lineWidth = 1;
    ctx.setLineDash([]);
    [lo + pad, (lo + hi) / 2, hi - pad].forEach(function (y) {
      ctx.beginPath(); ctx.moveTo(left, Y(y)); ctx.lineTo(w - 4, Y(y)); ctx.stroke();
      ctx.fillText(fmt(y, Math.abs(hi - lo) < 10 ? 2 : 0), 2, Y(y) + 3);
    });
    ctx.fillText(fmt(x0, 1) + " s", left, h - 4);
    ctx.fillText(fmt(x1, 1) + " s", w - 40, h - 4);
    series.forEach(function (s) {
      ctx.strokeStyle = s.color; ctx.globalAlpha = s.dash ? 0.6 : 1; ctx.lineWidth = s.dash ? 1 : 1.5;
      ctx.setLineDash(s.dash ? [4, 4] : []);
      ctx.beginPath();
      s.ys.forEach(function (y, i) { if (i) ctx.lineTo(X(xs[i]), Y(y)); else ctx.moveTo(X(xs[i]), Y(y)); });
      ctx.stroke();
    });
    ctx.globalAlpha = 1; ctx.setLineDash([]); ctx.strokeStyle = "#e8590c"; ctx.lineWidth = 1.5;
    ctx.beginPath(); ctx.moveTo(X(st.time), 2); ctx.lineTo(X(st.time), h - bottom); ctx.stroke();
  }

  // ---------- the clock

  function tick(now) {
    if (st.playing && st.ready) {
      if (st.lastTick !== null) {
        st.time = Math.min(st.time + (now - st.lastTick) / 1000 * st.speed, meta.endS);
        if (st.time >= meta.endS) pause();
      }
      st.lastTick = now;
      draw();
    } else {
      st.lastTick = null;
    }
    requestAnimationFrame(tick);
  }

  // ---------- loading

  function unpack(id, Type) {
    var text = document.getElementById(id).textContent.trim();
    var raw = atob(text), bytes = new Uint8Array(raw.length);
    for (var i = 0; i < raw.length; i++) bytes[i] = raw.charCodeAt(i);
    var stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("gzip"));
    return new Response(stream).arrayBuffer().then(function (buffer) { return new Type(buffer); });
  }

  var markTimes = new Float64Array(0), objectTimes = meta.objectChanges.map(function (c) { return c[0]; });

  function load() {
    if (typeof DecompressionStream === "undefined") {
      return Promise.reject(new Error("this browser cannot unpack it (no DecompressionStream)"));
    }
    return Promise.all([
      unpack("c2rviz-times", Float64Array), unpack("c2rviz-values", Float32Array),
      unpack("c2rviz-marks", Float64Array)
    ]).then(function (arrays) {
      data = { times: arrays[0], values: arrays[1], marks: arrays[2] };
      if (data.values.length !== data.times.length * width || data.times.length !== meta.frames) {
        throw new Error("its frames do not add up");
      }
      var count = data.marks.length / 13;
      markTimes = new Float64Array(count);
      lastClear = new Int32Array(count);
      var clear = -1;
      for (var i = 0; i < count; i++) {
        markTimes[i] = data.marks[i * 13];
        if (data.marks[i * 13 + 1] !== 0) clear = i;
        lastClear[i] = clear;
      }
    });
  }

  function whenViser(started) {
    if (sceneReady()) return Promise.resolve();
    return new Promise(function (resolve, reject) {
      (function poll() {
        if (sceneReady()) resolve();
        else if (Date.now() - started > VISER_WAIT_MS) reject(new Error("the 3D view did not start"));
        else setTimeout(poll, 30);
      })();
    });
  }

  function partPoses(k) {  // each part's pose in frame k: x, y, z [m], roll, pitch, yaw [rad]
    var out = {};
    parts.forEach(function (part, i) { out[part.name] = partPose(k, i); });
    return out;
  }

  var api = {
    state: function () {
      var k = st.frame;
      return {
        ready: st.ready, time: st.time, frame: k, frames: data.times.length,
        frameTime: k >= 0 && data.times.length ? data.times[k] : null,
        q: k >= 0 && data.times.length ? Array.prototype.slice.call(data.values.subarray(k * width, k * width + n)) : null,
        markers: st.markersShown, objects: st.objectsShown.slice(), playing: st.playing,
        parts: k >= 0 && data.times.length ? partPoses(k) : {},
        speed: st.speed, window: st.window, plotCursor: st.plotCursor, plotRange: st.plotRange,
        plotDraws: st.plotDraws, problems: st.problems.slice(), refused: st.refused, endS: meta.endS,
        timings: st.timings
      };
    },
    seek: function (t) { pause(); return seek(t); },
    typeTime: typedTime,
    step: step, play: play, pause: pause, setSpeed: setSpeed, setWindow: setWindow,
    poseLinks: poseLinks, rpyQuat: rpyQuat
  };
  window.__c2rvizPlayer = api;

  function start() {
    buildUi();
    var started = Date.now();
    st.timings = { start: performance.now() };
    var loaded = load().then(function () { st.timings.data = performance.now(); });
    var shown = whenViser(started).then(function () { st.timings.scene = performance.now(); });
    Promise.all([loaded, shown]).then(function () {
      st.ready = true;
      st.timings.ready = performance.now();
      redraw();
      if (data.times.length > 1) play();
    }).catch(function (error) {
      problem("this recording cannot be played: " + error.message);
      st.ready = data.times.length > 0 && sceneReady();
      redraw();
    });
    requestAnimationFrame(tick);
  }

  if (document.readyState === "loading") document.addEventListener("DOMContentLoaded", start);
  else start();
})();

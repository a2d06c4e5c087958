/* motionlab web player: skeletons drawn with three.js (window.THREE) when the page has it, else
 * with the browser's own 2D canvas (same camera, bones as round-capped strokes, far ones first).
 * motionlab.viz.web fills in __PLAYER_ID__; the motion is the JSON in the div's
 * <script type="application/json" class="motionlab-data">: per skeleton the root's path and the
 * joints relative to it, in millimetres (int16, base64), Y up. */
(function () {
  "use strict";
  var root = document.getElementById("__PLAYER_ID__");
  if (!root || root.getAttribute("data-started")) return;
  root.setAttribute("data-started", "1");
  var message = root.querySelector(".motionlab-message");
  var FOV = 35 * Math.PI / 180;  // vertical field of view of both drawers
  // three.js may come from the page (the documentation site), from this output, or from an earlier
  // output of the same notebook (motionlab.viz.web.player embeds it once per kernel): wait for it a
  // little, then draw on the 2D canvas instead.
  var tries = 0;
  (function waitForThree() {
    if (window.THREE && window.THREE.WebGLRenderer) { start("three"); return; }
    if (++tries < 20) { setTimeout(waitForThree, 100); return; }
    start("canvas");
  })();

  function decode(s) {  // the joints relative to the root, millimetres (Int16Array, T * J * 3)
    var bytes = atob(s.joints), rel = new Int16Array(bytes.length / 2);
    for (var i = 0; i < rel.length; i++) {
      var v = bytes.charCodeAt(2 * i) | (bytes.charCodeAt(2 * i + 1) << 8);
      rel[i] = v > 32767 ? v - 65536 : v;
    }
    return rel;
  }
  function point(fig, frame, j) {  // world position of joint j at a frame, metres [x, y, z]
    var i = 3 * (frame * fig.joints + j), r = fig.s.root, f = 3 * frame;
    return [(r[f] + fig.rel[i]) / 1000, (r[f + 1] + fig.rel[i + 1]) / 1000, (r[f + 2] + fig.rel[i + 2]) / 1000];
  }

  function threeDrawer(THREE, canvas, data, figures) {
    var renderer = new THREE.WebGLRenderer({ canvas: canvas, antialias: true, preserveDrawingBuffer: true });
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    var scene = new THREE.Scene();
    scene.background = new THREE.Color(0xf5f6f8);
    scene.add(new THREE.HemisphereLight(0xffffff, 0x556677, 2.2));
    var sun = new THREE.DirectionalLight(0xffffff, 1.6);
    sun.position.set(3, 8, 5);
    scene.add(sun);
    var grid = new THREE.GridHelper(data.grid, Math.round(data.grid / 0.5), 0x9aa1a9, 0xd5d9de);
    scene.add(grid);
    var camera = new THREE.PerspectiveCamera(FOV * 180 / Math.PI, 2, 0.01, 1000);
    var boneShape = new THREE.CylinderGeometry(1, 1, 1, 10), jointShape = new THREE.SphereGeometry(1, 14, 10);
    var meshes = figures.map(function (fig) {
      var material = new THREE.MeshLambertMaterial({ color: fig.s.color });
      var bones = new THREE.InstancedMesh(boneShape, material, Math.max(fig.joints - 1, 1));
      bones.count = fig.joints - 1;
      var balls = new THREE.InstancedMesh(jointShape, material, fig.joints);
      scene.add(bones);
      scene.add(balls);
      return { bones: bones, balls: balls };
    });
    var matrix = new THREE.Matrix4(), turn = new THREE.Quaternion(), up = new THREE.Vector3(0, 1, 0);
    var a = new THREE.Vector3(), b = new THREE.Vector3(), dir = new THREE.Vector3(), size = new THREE.Vector3();
    return {
      resize: function (width, height) {
        renderer.setSize(width, height, false);
        camera.aspect = width / height;
        camera.updateProjectionMatrix();
      },
      draw: function (frames, eye, target, centre) {
        figures.forEach(function (fig, n) {
          var r = fig.s.radius, k = 0;
          for (var j = 0; j < fig.joints; j++) {
            a.fromArray(point(fig, frames[n], j));
            matrix.compose(a, turn.identity(), size.set(1.6 * r, 1.6 * r, 1.6 * r));
            meshes[n].balls.setMatrixAt(j, matrix);
            var p = fig.s.parents[j];
            if (p < 0) continue;
            b.fromArray(point(fig, frames[n], p));
            dir.subVectors(a, b);
            var length = dir.length();
            turn.setFromUnitVectors(up, length > 1e-9 ? dir.divideScalar(length) : up);
            matrix.compose(b.add(a).multiplyScalar(0.5), turn, size.set(r, length, r));
            meshes[n].bones.setMatrixAt(k++, matrix);
          }
          meshes[n].bones.instanceMatrix.needsUpdate = true;
          meshes[n].balls.instanceMatrix.needsUpdate = true;
        });
        camera.position.fromArray(eye);
        camera.lookAt(target[0], target[1], target[2]);
        grid.position.set(Math.round(centre[0]), 0, Math.round(centre[2]));
        renderer.render(scene, camera);
      },
    };
  }

  function canvasDrawer(canvas, data, figures) {
    var ctx = canvas.getContext("2d"), scale = window.devicePixelRatio || 1, width = 1, height = 1;
    function sub(p, q) { return [p[0] - q[0], p[1] - q[1], p[2] - q[2]]; }
    function cross(p, q) { return [p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0]]; }
    function unit(p) { var n = Math.hypot(p[0], p[1], p[2]) || 1; return [p[0] / n, p[1] / n, p[2] / n]; }
    function dot(p, q) { return p[0] * q[0] + p[1] * q[1] + p[2] * q[2]; }
    function camera(eye, target) {  // world point -> [x, y, depth] in CSS pixels (depth <= 0: behind)
      var f = unit(sub(target, eye)), r = unit(cross(f, [0, 1, 0])), u = cross(r, f);
      var focal = 0.5 * height / Math.tan(FOV / 2);
      return function (p) {
        var d = sub(p, eye), z = dot(d, f);
        return [0.5 * width + focal * dot(d, r) / z, 0.5 * height - focal * dot(d, u) / z, z, focal / z];
      };
    }
    function floor(project, centre) {  // the grid: 0.5 m squares, drawn piece by piece in front of the eye
      var half = data.grid / 2, cx = Math.round(centre[0]), cz = Math.round(centre[2]);
      ctx.lineWidth = 1;
      for (var i = 0, n = Math.round(data.grid / 0.5); i <= n; i++) {
        var c = -half + 0.5 * i;
        ctx.strokeStyle = Math.abs(c) < 1e-9 ? "#9aa1a9" : "#d5d9de";
        for (var s = 0; s < n; s++) {
          var t0 = -half + 0.5 * s, t1 = t0 + 0.5;
          [[[cx + c, 0, cz + t0], [cx + c, 0, cz + t1]], [[cx + t0, 0, cz + c], [cx + t1, 0, cz + c]]].forEach(function (seg) {
            var p = project(seg[0]), q = project(seg[1]);
            if (p[2] < 0.05 || q[2] < 0.05) return;
            ctx.beginPath(); ctx.moveTo(p[0], p[1]); ctx.lineTo(q[0], q[1]); ctx.stroke();
          });
        }
      }
    }
    return {
      resize: function (w, h) {
        width = w; height = h;
        canvas.width = Math.round(w * scale); canvas.height = Math.round(h * scale);
      },
      draw: function (frames, eye, target, centre) {
        var project = camera(eye, target), strokes = [];
        ctx.setTransform(scale, 0, 0, scale, 0, 0);
        ctx.fillStyle = "#f5f6f8";
        ctx.fillRect(0, 0, width, height);
        floor(project, centre);
        figures.forEach(function (fig, n) {
          var at = [];
          for (var j = 0; j < fig.joints; j++) at.push(project(point(fig, frames[n], j)));
          for (j = 0; j < fig.joints; j++) {  // a ball at every joint, a bone to its parent
            var p = fig.s.parents[j], q = at[j], r = fig.s.radius;
            if (q[2] < 0.05) continue;
            strokes.push({ a: q, b: q, depth: q[2], width: 3.2 * r * q[3], color: fig.s.color });
            if (p < 0 || at[p][2] < 0.05) continue;
            strokes.push({ a: q, b: at[p], depth: 0.5 * (q[2] + at[p][2]), width: r * (q[3] + at[p][3]), color: fig.s.color });
          }
        });
        strokes.sort(function (x, y) { return y.depth - x.depth; });  // far first
        ctx.lineCap = "round";
        strokes.forEach(function (s) {
          ctx.strokeStyle = s.color;
          ctx.lineWidth = Math.max(s.width, 1.5);
          ctx.beginPath(); ctx.moveTo(s.a[0], s.a[1]); ctx.lineTo(s.b[0] + 1e-3, s.b[1]); ctx.stroke();
        });
      },
    };
  }

  function start(kind) {
    var data = JSON.parse(root.querySelector("script.motionlab-data").textContent);
    var canvas = root.querySelector("canvas");
    var figures = data.skeletons.map(function (s) {
      return { s: s, rel: decode(s), joints: s.parents.length, frames: s.root.length / 3 };
    });
    var drawer;
    try {
      drawer = kind === "three" ? threeDrawer(window.THREE, canvas, data, figures) : canvasDrawer(canvas, data, figures);
    } catch (err) {
      message.textContent = "The player could not draw in this browser (" + err.message + ").";
      return;
    }
    message.textContent = kind === "three" ? "" : "drawn without three.js (the browser's 2D canvas)";
    message.style.color = "#888";
    root.setAttribute("data-renderer", kind);
    controls(data, figures, canvas, drawer);
  }

  function controls(data, figures, canvas, drawer) {
    var view = { azimuth: 0.6, elevation: 0.25, distance: data.distance };
    var state = { t: 0, playing: false, last: null, dirty: true };
    var play = root.querySelector("button.motionlab-play");
    var slider = root.querySelector("input.motionlab-time");
    var label = root.querySelector(".motionlab-label");
    slider.max = String(data.duration);
    slider.step = String(1 / data.fps);
    function setPlaying(on) {
      state.playing = on;
      state.last = null;
      play.textContent = on ? "\u275a\u275a pause" : "\u25b6 play";
      root.setAttribute("data-playing", on ? "1" : "0");
    }
    play.addEventListener("click", function () { setPlaying(!state.playing); state.dirty = true; });
    slider.addEventListener("input", function () { state.t = parseFloat(slider.value); state.dirty = true; });
    var drag = null;
    canvas.addEventListener("pointerdown", function (e) { drag = [e.clientX, e.clientY]; canvas.setPointerCapture(e.pointerId); });
    canvas.addEventListener("pointerup", function () { drag = null; });
    canvas.addEventListener("pointermove", function (e) {
      if (!drag) return;
      view.azimuth -= 0.008 * (e.clientX - drag[0]);
      view.elevation = Math.max(-0.2, Math.min(1.45, view.elevation + 0.008 * (e.clientY - drag[1])));
      drag = [e.clientX, e.clientY];
      state.dirty = true;
    });
    canvas.addEventListener("wheel", function (e) {
      e.preventDefault();
      view.distance = Math.max(0.3, Math.min(200, view.distance * Math.exp(0.001 * e.deltaY)));
      state.dirty = true;
    }, { passive: false });
    function resize() {
      drawer.resize(Math.max(canvas.clientWidth, 50), Math.max(canvas.clientHeight, 50));
      state.dirty = true;
    }
    if (window.ResizeObserver) new ResizeObserver(resize).observe(canvas);
    resize();
    function frame(now) {
      if (state.playing) {
        if (state.last !== null) state.t = (state.t + (now - state.last) / 1000) % Math.max(data.duration, 1e-6);
        state.last = now;
        slider.value = String(state.t);
        state.dirty = true;
      }
      if (state.dirty) {
        var frames = figures.map(function (fig) { return Math.min(Math.floor(state.t * fig.s.fps + 1e-6), fig.frames - 1); });
        var centre = [0, 0, 0];  // the mean root position: where the camera looks
        figures.forEach(function (fig, n) {
          var p = point(fig, frames[n], 0);
          for (var i = 0; i < 3; i++) centre[i] += p[i] / figures.length;
        });
        var target = [centre[0], data.middle !== undefined ? data.middle : data.height * 0.5, centre[2]];
        var ce = Math.cos(view.elevation);
        var eye = [target[0] + view.distance * ce * Math.sin(view.azimuth), target[1] + view.distance * Math.sin(view.elevation),
                   target[2] + view.distance * ce * Math.cos(view.azimuth)];
        drawer.draw(frames, eye, target, centre);
        label.textContent = "t = " + state.t.toFixed(2) + " s / " + data.duration.toFixed(2) + " s";
        state.dirty = false;
      }
      requestAnimationFrame(frame);
    }
    setPlaying(data.autoplay);
    root.setAttribute("data-ready", "1");
    requestAnimationFrame(frame);
  }
})();

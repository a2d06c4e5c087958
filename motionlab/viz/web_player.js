/* motionlab web player: skeletons drawn with three.js (window.THREE), one <div> per player.
 * motionlab.viz.web fills in __PLAYER_ID__; the motion is the JSON in the div's
 * <script type="application/json" class="motionlab-data">: per skeleton the root's path and the
 * joints relative to it, in millimetres (int16, base64), Y up. */
(function () {
  "use strict";
  var root = document.getElementById("__PLAYER_ID__");
  if (!root || root.getAttribute("data-started")) return;
  root.setAttribute("data-started", "1");
  var message = root.querySelector(".motionlab-message");
  // three.js may come from the page (the documentation site), from this output, or from an earlier
  // output of the same notebook (motionlab.viz.web.player embeds it once per kernel): wait for it.
  var tries = 0;
  (function waitForThree() {
    if (window.THREE && window.THREE.WebGLRenderer) { message.textContent = ""; start(window.THREE); return; }
    if (++tries < 50) { setTimeout(waitForThree, 100); return; }
    message.textContent = "The 3D player needs three.js, which is not loaded on this page. The documentation " +
      "site includes it; in JupyterLab run `bash scripts/vendor_three.sh` once, then run the notebook again " +
      "(motionlab.viz.web.player embeds the file in the first player's output).";
  })();
  function start(THREE) {
  var data = JSON.parse(root.querySelector("script.motionlab-data").textContent);
  var canvas = root.querySelector("canvas");
  var renderer;
  try {
    renderer = new THREE.WebGLRenderer({ canvas: canvas, antialias: true, preserveDrawingBuffer: true });
  } catch (err) {
    message.textContent = "WebGL is not available in this browser (" + err.message + ").";
    return;
  }
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  var scene = new THREE.Scene();
  scene.background = new THREE.Color(0xf5f6f8);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x556677, 2.2));
  var sun = new THREE.DirectionalLight(0xffffff, 1.6);
  sun.position.set(3, 8, 5);
  scene.add(sun);
  var grid = new THREE.GridHelper(data.grid, Math.round(data.grid / 0.5), 0x9aa1a9, 0xd5d9de);
  scene.add(grid);
  var camera = new THREE.PerspectiveCamera(35, 2, 0.01, 1000);

  var boneShape = new THREE.CylinderGeometry(1, 1, 1, 10);
  var jointShape = new THREE.SphereGeometry(1, 14, 10);
  var figures = data.skeletons.map(function (s) {
    var material = new THREE.MeshLambertMaterial({ color: s.color });
    var joints = s.parents.length;
    var bytes = atob(s.joints), rel = new Int16Array(bytes.length / 2);
    for (var i = 0; i < rel.length; i++) {
      var v = bytes.charCodeAt(2 * i) | (bytes.charCodeAt(2 * i + 1) << 8);
      rel[i] = v > 32767 ? v - 65536 : v;
    }
    var bones = new THREE.InstancedMesh(boneShape, material, Math.max(joints - 1, 1));
    bones.count = joints - 1;
    var balls = new THREE.InstancedMesh(jointShape, material, joints);
    scene.add(bones);
    scene.add(balls);
    return { s: s, rel: rel, bones: bones, balls: balls, joints: joints, frames: s.root.length / 3 };
  });

  var matrix = new THREE.Matrix4(), turn = new THREE.Quaternion(), up = new THREE.Vector3(0, 1, 0);
  var a = new THREE.Vector3(), b = new THREE.Vector3(), dir = new THREE.Vector3(), size = new THREE.Vector3();
  function point(fig, frame, j, out) {
    var i = 3 * (frame * fig.joints + j), r = fig.s.root, f = 3 * frame;
    return out.set((r[f] + fig.rel[i]) / 1000, (r[f + 1] + fig.rel[i + 1]) / 1000, (r[f + 2] + fig.rel[i + 2]) / 1000);
  }
  function pose(t) {  // draw every skeleton at time t (seconds); returns the mean root position
    var centre = new THREE.Vector3();
    figures.forEach(function (fig) {
      var frame = Math.min(Math.floor(t * fig.s.fps + 1e-6), fig.frames - 1), k = 0;
      var r = fig.s.radius;
      for (var j = 0; j < fig.joints; j++) {
        point(fig, frame, j, a);
        matrix.compose(a, turn.identity(), size.set(1.6 * r, 1.6 * r, 1.6 * r));
        fig.balls.setMatrixAt(j, matrix);
        var p = fig.s.parents[j];
        if (p < 0) { centre.add(a); continue; }
        point(fig, frame, p, b);
        dir.subVectors(a, b);
        var length = dir.length();
        turn.setFromUnitVectors(up, length > 1e-9 ? dir.divideScalar(length) : up);
        matrix.compose(b.add(a).multiplyScalar(0.5), turn, size.set(r, length, r));
        fig.bones.setMatrixAt(k++, matrix);
      }
      fig.bones.instanceMatrix.needsUpdate = true;
      fig.balls.instanceMatrix.needsUpdate = true;
    });
    return centre.divideScalar(figures.length);
  }

  var view = { azimuth: 0.6, elevation: 0.25, distance: data.distance, target: new THREE.Vector3() };
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
    var width = Math.max(canvas.clientWidth, 50), height = Math.max(canvas.clientHeight, 50);
    renderer.setSize(width, height, false);
    camera.aspect = width / height;
    camera.updateProjectionMatrix();
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
      var centre = pose(state.t);
      view.target.set(centre.x, data.middle !== undefined ? data.middle : data.height * 0.5, centre.z);
      var ce = Math.cos(view.elevation);
      camera.position.set(
        view.target.x + view.distance * ce * Math.sin(view.azimuth),
        view.target.y + view.distance * Math.sin(view.elevation),
        view.target.z + view.distance * ce * Math.cos(view.azimuth));
      camera.lookAt(view.target);
      grid.position.set(Math.round(centre.x), 0, Math.round(centre.z));
      renderer.render(scene, camera);
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

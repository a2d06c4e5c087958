// World joint positions of a .glb as three.js computes them (GLTFLoader + AnimationMixer), for
// tests/core/test_gltf.py. Usage: node gltf_threejs.mjs THREE_PACKAGE_DIR FILE.glb T0 T1 ...
// Prints JSON {"names": [...], "positions": [[[x, y, z] per joint] per time]}.
import { readFileSync } from "node:fs";
import { pathToFileURL } from "node:url";

const [threeDir, glbPath, ...times] = process.argv.slice(2);
const THREE = await import(pathToFileURL(`${threeDir}/build/three.module.js`));
const { GLTFLoader } = await import(pathToFileURL(`${threeDir}/examples/jsm/loaders/GLTFLoader.js`));
const bytes = readFileSync(glbPath);
const buffer = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
new GLTFLoader().parse(buffer, "", (gltf) => {
  const skinned = [];
  gltf.scene.traverse((o) => { if (o.isSkinnedMesh) skinned.push(o); });
  const bones = skinned[0].skeleton.bones;  // in the skin's joint order
  const mixer = new THREE.AnimationMixer(gltf.scene);
  mixer.clipAction(gltf.animations[0]).play();
  const positions = times.map((t) => {
    mixer.setTime(parseFloat(t));
    gltf.scene.updateMatrixWorld(true);
    return bones.map((b) => b.getWorldPosition(new THREE.Vector3()).toArray());
  });
  console.log(JSON.stringify({ names: bones.map((b) => b.name), positions }));
}, (err) => { console.error(String(err)); process.exit(1); });

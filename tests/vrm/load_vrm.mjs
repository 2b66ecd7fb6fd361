// Loads .vrm files with the reference VRM loader (@pixiv/three-vrm on three.js's GLTFLoader) in
// Node and prints, per file, one JSON line: the spec version, the meta, the humanoid bones found,
// the required bones missing, and the first-person split (triangles of the mesh with and without
// the head). Exit 1 if a file does not load as VRM 1.0 with every required humanoid bone, 0
// otherwise. Usage: node load_vrm.mjs FILE.vrm ...
import { readFile } from 'node:fs/promises';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { VRMLoaderPlugin, VRMRequiredHumanBoneName } from '@pixiv/three-vrm';

const files = process.argv.slice(2);
if (files.length === 0) {
  console.error('usage: node load_vrm.mjs FILE.vrm ...');
  process.exit(2);
}

function parse(bytes) {
  const loader = new GLTFLoader();
  loader.register((parser) => new VRMLoaderPlugin(parser));
  const buffer = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
  return new Promise((resolve, reject) => loader.parse(buffer, '', resolve, reject));
}

function triangles(mesh) {
  const g = mesh.geometry;
  return (g.index ? g.index.count : g.attributes.position.count) / 3;
}

let failed = false;
for (const file of files) {
  try {
    const gltf = await parse(new Uint8Array(await readFile(file)));
    const vrm = gltf.userData.vrm;
    if (!vrm) throw new Error('three-vrm found no VRM in the file');
    const found = Object.keys(vrm.humanoid.humanBones).filter((b) => vrm.humanoid.getRawBoneNode(b));
    const missing = Object.values(VRMRequiredHumanBoneName).filter((b) => !found.includes(b));
    // First person: setup() splits each `auto` mesh into the whole body (third person only) and
    // a copy without the triangles weighted to the head (first person).
    vrm.firstPerson.setup();
    const meshes = [];
    vrm.scene.traverse((o) => { if (o.isMesh) meshes.push(o); });
    const fp = vrm.firstPerson;
    const tri = (layer) => meshes.filter((m) => m.layers.isEnabled(layer))
      .reduce((n, m) => n + triangles(m), 0);
    const report = {
      file,
      specVersion: gltf.parser.json.extensions?.VRMC_vrm?.specVersion ?? null,
      metaVersion: vrm.meta.metaVersion,
      meta: {
        name: vrm.meta.name, authors: vrm.meta.authors, licenseUrl: vrm.meta.licenseUrl,
        otherLicenseUrl: vrm.meta.otherLicenseUrl, thirdPartyLicenses: vrm.meta.thirdPartyLicenses,
      },
      generator: gltf.asset?.generator ?? null,
      humanBones: found,
      missingRequired: missing,
      firstPerson: {
        annotations: fp.meshAnnotations.map((a) => a.type),
        trianglesFirstPerson: tri(fp.firstPersonOnlyLayer),
        trianglesThirdPerson: tri(fp.thirdPersonOnlyLayer),
      },
    };
    console.log(JSON.stringify(report));
    if (report.specVersion !== '1.0' || report.metaVersion !== '1' || missing.length > 0) failed = true;
  } catch (e) {
    console.log(JSON.stringify({ file, error: String(e && e.message ? e.message : e) }));
    failed = true;
  }
}
process.exit(failed ? 1 : 0);

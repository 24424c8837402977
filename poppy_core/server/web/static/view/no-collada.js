// The import map points urdf-loader's COLLADA import here: poppy's URDFs name STL meshes only,
// so the page ships no COLLADA loader (a .dae mesh is drawn as nothing, with one console line).
export class ColladaLoader {
  constructor() {}
  load(url, onLoad, onProgress, onError) {
    const error = new Error(`${url}: the 3D view draws STL meshes only`);
    if (onError) onError(error); else console.warn(error.message);
  }
}

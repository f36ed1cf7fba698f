// What the `.html` viewer page takes from three.js, bundled by bundle.sh into three.min.js,
// which the page inlines as a classic script (global `HALO4D_THREE`), so that the page needs
// no network and opens from file:// (a module script could not import from a file there).
export {
  AmbientLight,
  Box3,
  Color,
  DirectionalLight,
  OrthographicCamera,
  PerspectiveCamera,
  Scene,
  Vector3,
  WebGLRenderer,
} from 'three';
export { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
export { OrbitControls } from 'three/addons/controls/OrbitControls.js';

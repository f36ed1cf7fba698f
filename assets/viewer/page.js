// The `.html` viewer page's own script (halo4d's src/export/html.rs inlines it after
// three.min.js): shows the `.glb` embedded in the page (base64, element #halo4d-glb) through
// its camera, the file's default glTF scene (surfaces in their colours of w, the curves), the
// halos hidden (they are the file's second scene; the checkbox shows them); drag to turn,
// scroll to zoom. Sets `window.HALO4D_READY` once the first frame is drawn, or
// `window.HALO4D_ERROR` to what went wrong, which the page shows too.
(() => {
  const T = window.HALO4D_THREE;
  const status = document.getElementById('halo4d-status');
  const fail = (e) => {
    window.HALO4D_ERROR = String((e && e.message) || e);
    status.textContent = 'cannot show the file: ' + window.HALO4D_ERROR;
  };
  try {
    const text = document.getElementById('halo4d-glb').textContent.trim();
    const binary = atob(text);
    const bytes = new Uint8Array(binary.length);
    for (let i = 0; i < binary.length; i += 1) bytes[i] = binary.charCodeAt(i);
    const page = JSON.parse(document.getElementById('halo4d-page').textContent);

    const renderer = new T.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    renderer.setPixelRatio(window.devicePixelRatio);
    renderer.setSize(window.innerWidth, window.innerHeight);
    document.body.appendChild(renderer.domElement);
    const scene = new T.Scene();
    // The picture's background, linear RGB as the scene gives it (three.js's working space).
    scene.background = new T.Color().setRGB(...page.background);

    new T.GLTFLoader().parse(bytes.buffer, '', (gltf) => {
      try {
        scene.add(gltf.scene);
        const halos = gltf.scenes.find((s) => s.name === page.halo_scene);
        let camera = null;
        gltf.scene.traverse((o) => {
          if (!camera && o.isCamera) camera = o;
        });
        const box = new T.Box3().setFromObject(gltf.scene);
        const centre = box.getCenter(new T.Vector3());
        const size = box.getSize(new T.Vector3()).length() || 1;
        let target = centre;
        if (camera) {
          // The node's world transform as the camera's own, so that the controls turn it.
          camera.updateWorldMatrix(true, false);
          camera.matrixWorld.decompose(camera.position, camera.quaternion, camera.scale);
          camera.removeFromParent();
          const picture = camera.userData.picture;
          if (picture && Array.isArray(picture.target)) target = new T.Vector3(...picture.target);
        } else {
          camera = new T.PerspectiveCamera(38, 1, size * 1e-3, size * 10);
          camera.position.copy(centre).add(new T.Vector3(0, 0, 2 * size));
        }
        // Lights that turn with the eye: a key light above left, a fill light right, and
        // some ambient, as the picture lights the surfaces.
        const key = new T.DirectionalLight(0xffffff, 2.2);
        key.position.set(-1, 1, 1);
        const fill = new T.DirectionalLight(0xffffff, 0.7);
        fill.position.set(1, 0, 0.6);
        for (const light of [key, fill]) {
          camera.add(light);
          camera.add(light.target);
          light.target.position.set(0, 0, -1);
        }
        scene.add(new T.AmbientLight(0xffffff, 0.6));
        scene.add(camera);

        const resize = () => {
          const aspect = window.innerWidth / window.innerHeight;
          if (camera.isPerspectiveCamera) {
            camera.aspect = aspect;
          } else {
            const half = (camera.top - camera.bottom) / 2;
            camera.left = -half * aspect;
            camera.right = half * aspect;
          }
          camera.updateProjectionMatrix();
          renderer.setSize(window.innerWidth, window.innerHeight);
        };
        const draw = () => renderer.render(scene, camera);
        const controls = new T.OrbitControls(camera, renderer.domElement);
        controls.target.copy(target);
        controls.update();
        controls.addEventListener('change', draw);
        window.addEventListener('resize', () => {
          resize();
          draw();
        });
        const toggle = document.getElementById('halo4d-halos');
        if (halos) {
          toggle.addEventListener('change', () => {
            if (toggle.checked) scene.add(halos);
            else scene.remove(halos);
            draw();
          });
        } else {
          toggle.disabled = true;
        }
        resize();
        draw();
        window.HALO4D_READY = true;
      } catch (e) {
        fail(e);
      }
    }, fail);
  } catch (e) {
    fail(e);
  }
})();

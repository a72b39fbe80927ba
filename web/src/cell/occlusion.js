// Labels hidden behind solid geometry. The placed objects are drawn once more, off screen and at
// half the view's resolution, into a float target that holds each pixel's depth; a label whose
// point lies behind the surface drawn there (in all of the pixels around it, by more than a
// margin) is hidden. This runs when the view rests, not at every frame of a drag.

import * as THREE from "three";

function depthMaterial() {
  const material = new THREE.MeshBasicMaterial({ side: THREE.DoubleSide });
  material.onBeforeCompile = (shader) => {
    shader.fragmentShader = shader.fragmentShader.replace(
      "#include <dithering_fragment>",
      "gl_FragColor = vec4(gl_FragCoord.z, 0.0, 0.0, 1.0);",
    );
  };
  return material;
}

const FAR = new THREE.Color(1, 0, 0);

export class Occlusion {
  constructor(renderer) {
    this.renderer = renderer;
    this.material = depthMaterial();
    this.target = null;
    this.failed = false;
  }

  /** The depth of every pixel where `solid` is drawn (1: nothing there), or null when this
   * browser cannot draw into a float target. */
  depths(scene, camera, solid) {
    if (this.failed) return null;
    const size = this.renderer.getDrawingBufferSize(new THREE.Vector2());
    const width = Math.max(1, Math.ceil(size.x / 2));
    const height = Math.max(1, Math.ceil(size.y / 2));
    if (!this.target || this.target.width !== width || this.target.height !== height) {
      if (this.target) this.target.dispose();
      this.target = new THREE.WebGLRenderTarget(width, height, { type: THREE.FloatType });
      this.buffer = new Float32Array(width * height * 4);
    }
    // Everything but the solid objects is left out of this drawing.
    const shown = [];
    scene.traverse((object) => {
      if (object.visible && (object.isMesh || object.isLine || object.isPoints) && !isInside(object, solid)) {
        shown.push(object);
        object.visible = false;
      }
    });
    const background = scene.background;
    const clear = this.renderer.getClearColor(new THREE.Color());
    const alpha = this.renderer.getClearAlpha();
    try {
      scene.background = null;
      scene.overrideMaterial = this.material;
      this.renderer.setClearColor(FAR, 1);
      this.renderer.setRenderTarget(this.target);
      this.renderer.clear();
      this.renderer.render(scene, camera);
      this.renderer.readRenderTargetPixels(this.target, 0, 0, width, height, this.buffer);
    } catch (err) {
      this.failed = true;
      return null;
    } finally {
      this.renderer.setRenderTarget(null);
      scene.overrideMaterial = null;
      scene.background = background;
      this.renderer.setClearColor(clear, alpha);
      for (const object of shown) object.visible = true;
    }
    return { width, height, depth: this.buffer };
  }

  /** For each point (world coordinates): whether the solid objects hide it from the camera, by
   * more than its margin (`margins[i]`, else `margin`). */
  hidden(scene, camera, solid, points, margin, margins = []) {
    if (!points.length || !solid.visible) return points.map(() => false);
    const map = this.depths(scene, camera, solid);
    if (!map) return points.map(() => false);
    const direction = camera.getWorldDirection(new THREE.Vector3());
    const along = (p) => p.clone().sub(camera.position).dot(direction);
    const ndc = new THREE.Vector3();
    return points.map((point, index) => {
      ndc.copy(point).project(camera);
      if (Math.abs(ndc.x) > 1 || Math.abs(ndc.y) > 1 || ndc.z > 1) return false;
      const px = Math.floor(((ndc.x + 1) / 2) * map.width);
      const py = Math.floor(((ndc.y + 1) / 2) * map.height);
      // The farthest surface around the point: hidden only where it is covered all round.
      let farthest = 0;
      for (let dy = -1; dy <= 1; dy++) {
        for (let dx = -1; dx <= 1; dx++) {
          const x = Math.min(map.width - 1, Math.max(0, px + dx));
          const y = Math.min(map.height - 1, Math.max(0, py + dy));
          farthest = Math.max(farthest, map.depth[(y * map.width + x) * 4]);
        }
      }
      if (farthest >= 1) return false;
      const surface = new THREE.Vector3(ndc.x, ndc.y, farthest * 2 - 1).unproject(camera);
      return along(point) - along(surface) > (margins[index] ?? margin);
    });
  }
}

function isInside(object, group) {
  for (let o = object; o; o = o.parent) if (o === group) return true;
  return false;
}

// The 3D view: trajectory, loops, map points and lines, keyframe frusta, the camera, with orbit
// controls and an optional follow-camera. Built from the Foxglove messages as they arrive
// (foxglove.SceneUpdate line primitives, foxglove.PointCloud, foxglove.PoseInFrame).
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { LineSegments2 } from 'three/examples/jsm/lines/LineSegments2.js';
import { LineSegmentsGeometry } from 'three/examples/jsm/lines/LineSegmentsGeometry.js';
import { LineMaterial } from 'three/examples/jsm/lines/LineMaterial.js';

export class Scene {
  constructor(container) {
    // Colours arrive as Foxglove sends them (0..1 display values): drawn as they are, not treated as
    // linear light (which would lighten every colour on the way to the screen).
    THREE.ColorManagement.enabled = false;
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
    this.renderer.setPixelRatio(window.devicePixelRatio);
    this.renderer.setClearColor(0x101218);
    container.appendChild(this.renderer.domElement);
    this.scene = new THREE.Scene();
    // plumb's world is the first camera's optical frame (x right, y down, z forward): turned so
    // that -y is up on screen.
    this.world = new THREE.Group();
    this.world.rotation.x = Math.PI;
    this.scene.add(this.world);
    const grid = new THREE.GridHelper(20, 40, 0x3a3f4a, 0x23262e);
    grid.rotation.x = Math.PI;  // in the world frame: the plane y = 0
    this.world.add(grid);
    this.camera = new THREE.PerspectiveCamera(60, 1, 0.01, 500);
    this.camera.position.set(0.7, 0.9, 1.4);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.enableDamping = true;
    this.groups = new Map();  // channel -> THREE.Group of its current drawing
    this.materials = [];
    this.follow = true;
    this.cameraMarker = this.makeCameraMarker();
    this.cameraMarker.visible = false;
    this.world.add(this.cameraMarker);
    this.target = new THREE.Vector3();
    this.resize();
    window.addEventListener('resize', () => this.resize());
    const loop = () => {
      requestAnimationFrame(loop);
      this.render();
    };
    loop();
  }

  resize() {
    const w = window.innerWidth, h = window.innerHeight;
    this.renderer.setSize(w, h);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    for (const m of this.materials) m.resolution.set(w, h);
  }

  render() {
    if (this.follow && this.cameraMarker.visible) {
      const p = this.cameraMarker.getWorldPosition(new THREE.Vector3());
      const delta = p.clone().sub(this.controls.target).multiplyScalar(0.1);
      this.controls.target.add(delta);
      this.camera.position.add(delta);
    }
    this.controls.update();
    this.renderer.render(this.scene, this.camera);
  }

  makeCameraMarker() {
    const s = 0.12, hx = 0.5 * s, hy = 0.375 * s;
    const c = [[-hx, -hy, s], [hx, -hy, s], [hx, hy, s], [-hx, hy, s]];
    const points = [];
    for (let i = 0; i < 4; i++) {
      points.push(0, 0, 0, ...c[i], ...c[i], ...c[(i + 1) % 4]);
    }
    const marker = new THREE.Group();
    marker.add(this.segments(points, null, [1, 1, 0.2, 1], 3));
    return marker;
  }

  material(widthPx, vertexColors) {
    const m = new LineMaterial({ linewidth: widthPx, vertexColors, worldUnits: false });
    m.resolution.set(window.innerWidth, window.innerHeight);
    this.materials.push(m);
    return m;
  }

  // Flat xyz pairs (line list) -> one fat-line object; colors: flat rgb per point or null.
  segments(positions, colors, color, widthPx) {
    const geometry = new LineSegmentsGeometry();
    geometry.setPositions(positions);
    if (colors) geometry.setColors(colors);
    const m = this.material(widthPx, !!colors);
    if (!colors) m.color.setRGB(color[0], color[1], color[2]);
    return new LineSegments2(geometry, m);
  }

  replaceGroup(channel) {
    const old = this.groups.get(channel);
    if (old) {
      this.world.remove(old);
      old.traverse((o) => {
        if (o.geometry) o.geometry.dispose();
        if (o.material) {
          this.materials = this.materials.filter((m) => m !== o.material);
          o.material.dispose();
        }
      });
    }
    const group = new THREE.Group();
    this.groups.set(channel, group);
    this.world.add(group);
    return group;
  }

  setVisible(channel, visible) {
    const g = this.groups.get(channel);
    if (g) g.visible = visible;
    (this.hidden ??= new Set())[visible ? 'delete' : 'add'](channel);
  }

  // foxglove.SceneUpdate of line primitives. Returns the number of points drawn per entity id.
  sceneUpdate(channel, update) {
    const group = this.replaceGroup(channel);
    group.visible = !(this.hidden && this.hidden.has(channel));
    const counts = {};
    for (const entity of update.entities) {
      let n = 0;
      for (const line of entity.lines) {
        const pts = line.points;
        const perPoint = line.colors && line.colors.length === pts.length;
        const positions = [], colors = [];
        const push = (i) => {
          positions.push(pts[i].x, pts[i].y, pts[i].z);
          if (perPoint) colors.push(line.colors[i].r, line.colors[i].g, line.colors[i].b);
        };
        if (line.type === 2) {  // LINE_LIST
          for (let i = 0; i + 1 < pts.length; i += 2) { push(i); push(i + 1); }
        } else {  // LINE_STRIP (and LINE_LOOP, closed below)
          for (let i = 0; i + 1 < pts.length; i++) { push(i); push(i + 1); }
          if (line.type === 1 && pts.length > 2) { push(pts.length - 1); push(0); }
        }
        n += pts.length;
        if (positions.length === 0) continue;
        const c = line.color;
        group.add(this.segments(positions, perPoint ? colors : null, [c.r, c.g, c.b], Math.max(1, line.thickness)));
      }
      counts[entity.id] = n;
    }
    return counts;
  }

  // foxglove.PointCloud with float32 x, y, z fields.
  pointCloud(channel, cloud) {
    const group = this.replaceGroup(channel);
    group.visible = !(this.hidden && this.hidden.has(channel));
    const bytes = Uint8Array.from(atob(cloud.data), (ch) => ch.charCodeAt(0));
    const view = new DataView(bytes.buffer);
    const offset = {};
    for (const f of cloud.fields) offset[f.name] = f.offset;
    const n = Math.floor(bytes.length / cloud.point_stride);
    const positions = new Float32Array(n * 3);
    for (let i = 0; i < n; i++) {
      const base = i * cloud.point_stride;
      positions[i * 3] = view.getFloat32(base + offset.x, true);
      positions[i * 3 + 1] = view.getFloat32(base + offset.y, true);
      positions[i * 3 + 2] = view.getFloat32(base + offset.z, true);
    }
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
    group.add(new THREE.Points(geometry, new THREE.PointsMaterial({ color: 0xd0d4dc, size: 2, sizeAttenuation: false })));
    return n;
  }

  // Looks at the whole of what `channel` draws (a finished run: its trajectory), from above.
  fitTo(channel) {
    const group = this.groups.get(channel);
    if (!group) return;
    const box = new THREE.Box3().setFromObject(group);
    if (box.isEmpty()) return;
    const center = box.getCenter(new THREE.Vector3());
    const size = Math.max(0.5, box.getSize(new THREE.Vector3()).length());
    this.controls.target.copy(center);
    this.camera.position.copy(center).add(new THREE.Vector3(0.35, 0.8, 0.5).multiplyScalar(size));
  }

  // foxglove.PoseInFrame of the camera.
  cameraPose(pose) {
    const p = pose.pose.position, q = pose.pose.orientation;
    const first = !this.cameraMarker.visible;
    this.cameraMarker.position.set(p.x, p.y, p.z);
    this.cameraMarker.quaternion.set(q.x, q.y, q.z, q.w);
    this.cameraMarker.visible = true;
    if (first && this.follow) {
      const w = this.cameraMarker.getWorldPosition(new THREE.Vector3());
      this.controls.target.copy(w);
      this.camera.position.copy(w).add(new THREE.Vector3(0.7, 0.9, 1.4));
    }
  }
}

// Draws foxglove.SceneUpdate entities (JSON form) with three.js: spheres as
// instanced meshes (one per opacity, so predicted spheres keep their
// per-action shading), cubes, cylinders, line lists and strips. World frame
// "world", z up, metres. Keeps a summary of every entity for tests.
import * as THREE from "three";
import { LineMaterial } from "three/examples/jsm/lines/LineMaterial.js";
import { LineSegments2 } from "three/examples/jsm/lines/LineSegments2.js";
import { LineSegmentsGeometry } from "three/examples/jsm/lines/LineSegmentsGeometry.js";

const sphereGeometry = new THREE.SphereGeometry(1, 12, 8);
// Faint spheres (predictions, ghost poses) overlap by the hundred; fewer
// triangles each keep software rendering (no GPU) affordable.
const faintSphereGeometry = new THREE.SphereGeometry(1, 8, 6);
const boxGeometry = new THREE.BoxGeometry(1, 1, 1);
const cylinderGeometry = new THREE.CylinderGeometry(0.5, 0.5, 1, 24).rotateX(Math.PI / 2);  // axis along z

function toColor(c) {
  return new THREE.Color(c.r, c.g, c.b);
}

function material(alpha, color) {
  return new THREE.MeshLambertMaterial({ color: color ?? 0xffffff, transparent: alpha < 0.999, opacity: alpha,
    depthWrite: alpha >= 0.999 });
}

function poseInto(obj, pose) {
  obj.position.set(pose.position.x, pose.position.y, pose.position.z);
  const q = pose.orientation;
  obj.quaternion.set(q.x, q.y, q.z, q.w);
}

class EntityView {
  constructor(root, id, resolution) {
    this.id = id;
    this.resolution = resolution;  // canvas size in px (fat lines need it)
    this.group = new THREE.Group();
    this.group.name = id;
    root.add(this.group);
    this.sphereMeshes = new Map();  // opacity key -> InstancedMesh
    this.others = [];
    this.summary = { spheres: 0, centroid: null, updates: 0, metadata: {} };
  }

  sphereMesh(key, alpha, needed) {
    let m = this.sphereMeshes.get(key);
    if (m && m.instanceMatrix.count < needed) {
      this.group.remove(m);
      m.dispose();
      m = undefined;
    }
    if (!m) {
      m = new THREE.InstancedMesh(alpha < 0.3 ? faintSphereGeometry : sphereGeometry, material(alpha), Math.max(16, needed * 2));
      m.renderOrder = alpha < 0.999 ? 1 : 0;
      this.sphereMeshes.set(key, m);
      this.group.add(m);
    }
    return m;
  }

  setSpheres(spheres) {
    const byKey = new Map();
    for (const s of spheres) {
      const key = Math.round(s.color.a * 40);
      if (!byKey.has(key)) byKey.set(key, []);
      byKey.get(key).push(s);
    }
    for (const [key, m] of this.sphereMeshes) if (!byKey.has(key)) m.count = 0;
    const mat = new THREE.Matrix4(), q = new THREE.Quaternion(), p = new THREE.Vector3(), sc = new THREE.Vector3();
    for (const [key, list] of byKey) {
      const m = this.sphereMesh(key, key / 40, list.length);
      list.forEach((s, i) => {
        p.set(s.pose.position.x, s.pose.position.y, s.pose.position.z);
        sc.set(s.size.x / 2, s.size.y / 2, s.size.z / 2);
        mat.compose(p, q, sc);
        m.setMatrixAt(i, mat);
        m.setColorAt(i, toColor(s.color));
      });
      m.count = list.length;
      m.instanceMatrix.needsUpdate = true;
      if (m.instanceColor) m.instanceColor.needsUpdate = true;
      m.computeBoundingSphere();
    }
  }

  clearOthers() {
    for (const o of this.others) {
      this.group.remove(o);
      if (o.geometry !== boxGeometry && o.geometry !== cylinderGeometry) o.geometry?.dispose?.();  // shared ones stay
      o.material?.dispose?.();
      if (o.isInstancedMesh) o.dispose();
    }
    this.others = [];
  }

  addOther(o) {
    this.others.push(o);
    this.group.add(o);
  }

  // Lines with their thickness (m, or px when scale_invariant), as Foxglove
  // draws them: three.js "fat" lines (plain WebGL lines are one pixel wide).
  setLines(lines) {
    for (const l of lines) {
      if (l.points.length < 2) continue;
      const flat = [];
      const pts = l.type === 1 ? [...l.points, l.points[0]] : l.points;  // a loop closes
      if (l.type === 2) for (const p of pts) flat.push(p.x, p.y, p.z);
      else pts.forEach((p, i) => { if (i > 0) flat.push(pts[i - 1].x, pts[i - 1].y, pts[i - 1].z, p.x, p.y, p.z); });
      const g = new LineSegmentsGeometry().setPositions(flat);
      const m = new LineMaterial({ color: toColor(l.color), transparent: l.color.a < 0.999, opacity: l.color.a,
        linewidth: l.thickness, worldUnits: !l.scale_invariant });
      m.resolution.copy(this.resolution);
      const obj = new LineSegments2(g, m);
      poseInto(obj, l.pose);
      obj.renderOrder = 2;
      this.addOther(obj);
    }
  }

  setSolids(cubes, cylinders) {
    if (cubes.length > 32) {  // a point cloud: one instanced mesh
      const m = new THREE.InstancedMesh(boxGeometry, material(1), cubes.length);
      const mat = new THREE.Matrix4(), p = new THREE.Vector3(), q = new THREE.Quaternion(), sc = new THREE.Vector3();
      cubes.forEach((c, i) => {
        p.set(c.pose.position.x, c.pose.position.y, c.pose.position.z);
        q.set(c.pose.orientation.x, c.pose.orientation.y, c.pose.orientation.z, c.pose.orientation.w);
        sc.set(c.size.x, c.size.y, c.size.z);
        m.setMatrixAt(i, mat.compose(p, q, sc));
        m.setColorAt(i, toColor(c.color));
      });
      this.addOther(m);
      cubes = [];
    }
    for (const [list, geometry] of [[cubes, boxGeometry], [cylinders, cylinderGeometry]]) {
      for (const c of list) {
        const mesh = new THREE.Mesh(geometry, material(c.color.a, toColor(c.color)));
        poseInto(mesh, c.pose);
        mesh.scale.set(c.size.x, c.size.y, c.size.z);
        this.addOther(mesh);
      }
    }
  }

  update(e) {
    this.clearOthers();
    this.setSpheres(e.spheres ?? []);
    this.setLines(e.lines ?? []);
    this.setSolids(e.cubes ?? [], e.cylinders ?? []);
    const s = this.summary;
    s.spheres = (e.spheres ?? []).length;
    s.cubes = (e.cubes ?? []).length;
    s.cylinders = (e.cylinders ?? []).length;
    s.lines = (e.lines ?? []).length;
    s.texts = (e.texts ?? []).map((t) => t.text);
    s.centroid = centroid(e.spheres ?? []);
    s.updates += 1;
    s.stamp = e.timestamp ? e.timestamp.sec + e.timestamp.nsec * 1e-9 : 0;
    s.metadata = Object.fromEntries((e.metadata ?? []).map((kv) => [kv.key, kv.value]));
  }

  dispose() {
    this.clearOthers();
    for (const m of this.sphereMeshes.values()) m.dispose();
    this.group.parent?.remove(this.group);
  }
}

function centroid(spheres) {
  if (!spheres.length) return null;
  const c = [0, 0, 0];
  for (const s of spheres) {
    c[0] += s.pose.position.x;
    c[1] += s.pose.position.y;
    c[2] += s.pose.position.z;
  }
  return c.map((v) => v / spheres.length);
}

export class SceneView {
  constructor(container) {
    this.renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: false });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio, 1.5));
    container.appendChild(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0xeef0f3);
    this.camera = new THREE.PerspectiveCamera(45, 1, 0.05, 50);
    this.camera.up.set(0, 0, 1);
    this.camera.position.set(2.0, 1.9, 1.5);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x667788, 1.6));
    const sun = new THREE.DirectionalLight(0xffffff, 1.4);
    sun.position.set(2, -3, 4);
    this.scene.add(sun);
    const grid = new THREE.GridHelper(4, 16, 0x99a0aa, 0xc8ccd2);
    grid.rotateX(Math.PI / 2);
    grid.position.z = -0.05;
    this.scene.add(grid);
    this.scene.add(new THREE.AxesHelper(0.3));
    this.root = new THREE.Group();
    this.scene.add(this.root);
    this.entities = new Map();
    this.container = container;
    this.lineResolution = new THREE.Vector2(1, 1);
    this.resize();
    window.addEventListener("resize", () => this.resize());
  }

  /** Renders `fraction` (0-1] of the device pixels in each direction. */
  setResolution(fraction) {
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio, 1.5) * fraction);
    this.resize();
  }

  resize() {
    const w = this.container.clientWidth, h = this.container.clientHeight;
    this.renderer.setSize(w, h);
    this.lineResolution.set(w, h);
    this.camera.aspect = w / Math.max(1, h);
    this.camera.updateProjectionMatrix();
  }

  /** Applies one foxglove.SceneUpdate. */
  apply(update) {
    for (const d of update.deletions ?? []) {
      const ids = d.type === 1 ? [...this.entities.keys()] : [d.id];
      for (const id of ids) {
        this.entities.get(id)?.dispose();
        this.entities.delete(id);
      }
    }
    for (const e of update.entities ?? []) {
      if (!this.entities.has(e.id)) this.entities.set(e.id, new EntityView(this.root, e.id, this.lineResolution));
      this.entities.get(e.id).update(e);
    }
  }

  clear() {
    for (const e of this.entities.values()) e.dispose();
    this.entities.clear();
  }

  summaries() {
    return Object.fromEntries([...this.entities].map(([id, e]) => [id, e.summary]));
  }

  /** CSS pixel position of a world point in the view's canvas. */
  project([x, y, z]) {
    const v = new THREE.Vector3(x, y, z).project(this.camera);
    const r = this.renderer.domElement.getBoundingClientRect();
    return { x: r.left + (v.x + 1) / 2 * r.width, y: r.top + (1 - v.y) / 2 * r.height };
  }

  render() {
    this.renderer.render(this.scene, this.camera);
  }
}

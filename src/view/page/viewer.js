// The review page of `dispex view` (src/view): the base's limit surface displaced by the map,
// the limit surface, the sculpt; colours by displacement, resolution, verify error and misses;
// a click picks a face. Everything comes from the JSON in #dispex-data; nothing is fetched.
//
// For programs (the browser test, tests/view/browser_test.py): window.dispexReady is true once
// the first frame is drawn (window.dispexError holds why it never will be), window.dispex the
// controls below; the URL's hash sets them too:
//   #surface=displaced|limit|sculpt&colour=displacement|resolution|error|holes|clay
//    &azimuth=DEG&elevation=DEG&zoom=F&lit=0|1&face=ID
(function () {
  'use strict';

  const statusEl = document.getElementById('status');
  function fail(message) {
    statusEl.textContent = message;
    statusEl.style.color = '#f99';
    window.dispexError = message;
  }

  // ---- Data ---------------------------------------------------------------------------------

  function bytesOf(text) {
    const s = atob(text);
    const bytes = new Uint8Array(s.length);
    for (let i = 0; i < s.length; ++i) bytes[i] = s.charCodeAt(i);
    return bytes;
  }
  function arrayOf(text, Type) {
    if (text === undefined || text === null) return null;
    const bytes = bytesOf(text);
    return new Type(bytes.buffer, 0, bytes.byteLength / Type.BYTES_PER_ELEMENT);
  }
  // 21-bit fixed point, two words a point (src/view/page_data.h, PackPoints).
  function unpackPoints(words, box) {
    const n = words.length / 2;
    const out = new Float32Array(3 * n);
    const k = 1 / 2097151;
    const s = [(box[3] - box[0]) * k, (box[4] - box[1]) * k, (box[5] - box[2]) * k];
    for (let i = 0; i < n; ++i) {
      const lo = words[2 * i], hi = words[2 * i + 1];
      out[3 * i] = box[0] + (lo & 0x1FFFFF) * s[0];
      out[3 * i + 1] = box[1] + ((lo >>> 21) | ((hi & 0x3FF) << 11)) * s[1];
      out[3 * i + 2] = box[2] + (hi >>> 10) * s[2];
    }
    return out;
  }

  // ---- Colours ------------------------------------------------------------------------------

  // The preview's signed colours (dispex preview --mode signed: green +, red -, intensity
  // |value| / range), over a dark grey so that the shape still shows where the value is 0.
  const GREY = 0.2;
  function signedColour(v, m, out, o) {
    if (!isFinite(v)) { out[o] = 1; out[o + 1] = 0; out[o + 2] = 1; return; }
    const c = m > 0 ? Math.round(255 * Math.min(1, Math.abs(v) / m)) / 255 : 0;
    out[o] = GREY + (1 - GREY) * (v < 0 ? c : 0);
    out[o + 1] = GREY + (1 - GREY) * (v > 0 ? c : 0);
    out[o + 2] = GREY;
  }
  const RAMP = [[0.27, 0.0, 0.33], [0.23, 0.32, 0.55], [0.13, 0.57, 0.55], [0.37, 0.79, 0.38],
                [0.99, 0.91, 0.15]];
  function ramp(t) {
    t = Math.max(0, Math.min(1, t)) * (RAMP.length - 1);
    const i = Math.min(RAMP.length - 2, Math.floor(t)), f = t - i;
    return [0, 1, 2].map((c) => RAMP[i][c] + f * (RAMP[i + 1][c] - RAMP[i][c]));
  }
  const GREEN = [0.1, 0.7, 0.2], YELLOW = [0.95, 0.85, 0.1], RED = [0.85, 0.1, 0.1];
  function errorColour(t) {  // t in tolerances
    const a = t <= 1 ? GREEN : YELLOW, b = t <= 1 ? YELLOW : RED, f = t <= 1 ? t : Math.min(1, t - 1);
    return [0, 1, 2].map((c) => a[c] + f * (b[c] - a[c]));
  }
  const UNKNOWN = [0.55, 0.55, 0.55], CONSTANT = [0.55, 0.55, 0.55], CLAY = [0.72, 0.7, 0.66];
  const NO_MISS = [0.6, 0.65, 0.72], ALL_MISSED = [0.85, 0.2, 0.85];
  const ORANGE = [1.0, 0.65, 0.2], DEEP_RED = [0.8, 0.05, 0.05];
  function css(c) {
    return 'rgb(' + c.map((x) => Math.round(255 * x)).join(',') + ')';
  }
  function fmt(x, digits) {
    if (x === null || x === undefined) return '-';
    if (typeof x !== 'number') return String(x);
    if (!isFinite(x)) return String(x);
    if (Number.isInteger(x) && Math.abs(x) < 1e15) return x.toLocaleString('en-US');
    return x.toPrecision(digits || 4);
  }
  function esc(text) {
    return String(text).replace(/[&<>"']/g, (c) => ({'&': '&amp;', '<': '&lt;', '>': '&gt;',
                                                     '"': '&quot;', "'": '&#39;'}[c]));
  }
  function table(rows) {
    return '<table class="kv">' + rows.filter((r) => r && r[1] !== undefined)
        .map((r) => '<tr><td>' + esc(r[0]) + '</td><td>' + esc(fmt(r[1], r[2])) + '</td></tr>')
        .join('') + '</table>';
  }
  function rawJson(label, value) {
    return '<details><summary>' + esc(label) + '</summary><pre>' +
           esc(JSON.stringify(value, null, 2)) + '</pre></details>';
  }

  // ---- The page -----------------------------------------------------------------------------

  function main() {
    const data = JSON.parse(document.getElementById('dispex-data').textContent);
    if (typeof THREE === 'undefined' || !THREE.OrbitControls) throw new Error('three.js is missing');
    const viewEl = document.getElementById('view');
    document.getElementById('title').textContent = data.title;

    // The surface: every face's grid, its points shared with its neighbours on its border.
    const S = data.surface;
    const quads = arrayOf(S.quads, Uint16Array);
    const numFaces = quads.length;
    const V = S.vertices;
    const limitP = unpackPoints(arrayOf(S.position, Uint32Array), S.box);
    const dq = arrayOf(S.displacement, Int16Array);
    const displacedP = new Float32Array(3 * V);
    for (let i = 0; i < 3 * V; ++i) displacedP[i] = limitP[i] + dq[i] * S.displacement_scale;
    const vq = arrayOf(S.value, Int16Array);
    const value = new Float32Array(V);
    let valueRange = 0;
    for (let i = 0; i < V; ++i) {
      value[i] = vq[i] * S.value_scale;
      valueRange = Math.max(valueRange, Math.abs(value[i]));
    }
    const border = arrayOf(S.border, Uint32Array);
    const slotStart = new Uint32Array(numFaces + 1), triStart = new Uint32Array(numFaces + 1);
    for (let f = 0; f < numFaces; ++f) {
      const n = quads[f];
      slotStart[f + 1] = slotStart[f] + (n ? (n + 1) * (n + 1) : 0);
      triStart[f + 1] = triStart[f] + 2 * n * n;
    }
    const numSlots = slotStart[numFaces], numTris = triStart[numFaces];
    const gid = new Uint32Array(numSlots);
    const index = new Uint32Array(3 * numTris);
    {
      let interior = 0, b = 0, t = 0;
      for (let f = 0; f < numFaces; ++f) {
        const n = quads[f], s0 = slotStart[f];
        for (let j = 0; j <= n && n; ++j) {
          for (let i = 0; i <= n; ++i) {
            const onBorder = i === 0 || j === 0 || i === n || j === n;
            gid[s0 + j * (n + 1) + i] = onBorder ? border[b++] : interior++;
          }
        }
        for (let j = 0; j < n; ++j) {
          for (let i = 0; i < n; ++i) {
            const a = s0 + j * (n + 1) + i;
            index[t++] = a; index[t++] = a + 1; index[t++] = a + n + 2;
            index[t++] = a; index[t++] = a + n + 2; index[t++] = a + n + 1;
          }
        }
      }
    }
    // Smooth normals over the shared points, per surface.
    function normalsOf(X) {
      const N = new Float32Array(3 * V);
      for (let t = 0; t < numTris; ++t) {
        const a = 3 * gid[index[3 * t]], b = 3 * gid[index[3 * t + 1]], c = 3 * gid[index[3 * t + 2]];
        const ux = X[b] - X[a], uy = X[b + 1] - X[a + 1], uz = X[b + 2] - X[a + 2];
        const vx = X[c] - X[a], vy = X[c + 1] - X[a + 1], vz = X[c + 2] - X[a + 2];
        const nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
        for (const k of [a, b, c]) { N[k] += nx; N[k + 1] += ny; N[k + 2] += nz; }
      }
      for (let i = 0; i < V; ++i) {
        const l = Math.hypot(N[3 * i], N[3 * i + 1], N[3 * i + 2]) || 1;
        N[3 * i] /= l; N[3 * i + 1] /= l; N[3 * i + 2] /= l;
      }
      return N;
    }
    const surfaces = {displaced: {P: displacedP, N: null}, limit: {P: limitP, N: null}};
    const slotPos = new Float32Array(3 * numSlots), slotNormal = new Float32Array(3 * numSlots);
    const slotColour = new Float32Array(3 * numSlots);
    const geometry = new THREE.BufferGeometry();
    const posAttr = new THREE.BufferAttribute(slotPos, 3);
    const normalAttr = new THREE.BufferAttribute(slotNormal, 3);
    const colourAttr = new THREE.BufferAttribute(slotColour, 3);
    geometry.setAttribute('position', posAttr);
    geometry.setAttribute('normal', normalAttr);
    geometry.setAttribute('color', colourAttr);
    geometry.setIndex(new THREE.BufferAttribute(index, 1));

    // Per face.
    const F = data.faces;
    const ulog2 = arrayOf(F.ulog2, Int8Array), vlog2 = arrayOf(F.vlog2, Int8Array);
    const constant = arrayOf(F.constant, Uint8Array);
    const baseFace = arrayOf(F.base_face, Int32Array), subFace = arrayOf(F.sub_face, Uint8Array);
    const samples = arrayOf(F.samples, Int32Array), misses = arrayOf(F.misses, Int32Array);
    const filled = arrayOf(F.filled, Int32Array), allMissed = arrayOf(F.all_missed, Uint8Array);
    const errorMapToSculpt = arrayOf(F.error_map_to_sculpt, Float32Array);
    const errorTruth = arrayOf(F.error_truth, Float32Array);
    const faceError = errorTruth || errorMapToSculpt;
    const errorName = errorTruth ? 'against the truth (largest |error| at its records)'
                                 : 'map to sculpt (largest distance on the face)';
    const withoutTile = new Set(F.without_tile || []);
    const discontinuous = new Set((data.map.meta && data.map.meta['dispex:discontinuous_faces']) || []);
    const tolerance = data.map.tolerance;
    let errorMax = 0;
    if (faceError) for (const e of faceError) if (isFinite(e)) errorMax = Math.max(errorMax, e);

    // The sculpt.
    let sculptMesh = null;
    if (data.sculpt) {
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(
          unpackPoints(arrayOf(data.sculpt.position, Uint32Array), data.sculpt.box), 3));
      g.setIndex(new THREE.BufferAttribute(arrayOf(data.sculpt.index, Uint32Array), 1));
      // The sculpt's own normals (8 bits a component), not the decimated triangles'.
      g.setAttribute('normal', new THREE.BufferAttribute(arrayOf(data.sculpt.normal, Int8Array), 3, true));
      sculptMesh = g;
    }

    // ---- Scene ----
    const renderer = new THREE.WebGLRenderer({antialias: true});
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    renderer.setClearColor(0x3b3f46);
    viewEl.insertBefore(renderer.domElement, viewEl.firstChild);
    const scene = new THREE.Scene();
    const camera = new THREE.PerspectiveCamera(30, 1, 0.01, 100);
    const ambient = new THREE.AmbientLight(0xffffff, 0.38);
    const light = new THREE.DirectionalLight(0xffffff, 0.72);
    scene.add(ambient, light, light.target);
    const materialOptions = {vertexColors: THREE.VertexColors, side: THREE.DoubleSide,
                             polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1};
    const litMaterial = new THREE.MeshPhongMaterial(
        Object.assign({shininess: 12, specular: 0x181818}, materialOptions));
    const flatMaterial = new THREE.MeshBasicMaterial(materialOptions);
    const surfaceObject = new THREE.Mesh(geometry, litMaterial);
    scene.add(surfaceObject);
    const sculptLit = new THREE.MeshPhongMaterial({color: new THREE.Color(CLAY[0], CLAY[1], CLAY[2]),
                                                  shininess: 12, specular: 0x181818,
                                                  side: THREE.DoubleSide});
    const sculptFlat = new THREE.MeshBasicMaterial({color: new THREE.Color(CLAY[0], CLAY[1], CLAY[2]),
                                                   side: THREE.DoubleSide});
    const sculptObject = sculptMesh ? new THREE.Mesh(sculptMesh, sculptLit) : null;
    if (sculptObject) { sculptObject.visible = false; scene.add(sculptObject); }
    const outline = new THREE.LineLoop(new THREE.BufferGeometry(),
                                       new THREE.LineBasicMaterial({color: 0xffee00}));
    outline.visible = false;
    scene.add(outline);
    const controls = new THREE.OrbitControls(camera, renderer.domElement);
    controls.enableDamping = false;
    controls.screenSpacePanning = true;

    const box = new THREE.Box3(new THREE.Vector3(S.box[0], S.box[1], S.box[2]),
                               new THREE.Vector3(S.box[3], S.box[4], S.box[5]));
    const centre = box.getCenter(new THREE.Vector3());
    const radius = Math.max(1e-9, 0.5 * box.getSize(new THREE.Vector3()).length());

    const state = {surface: 'displaced', colour: 'displacement', lit: true, azimuth: 45,
                   elevation: 35.26, zoom: 1, face: -1};
    let frameRequested = false;
    function requestFrame() {
      if (frameRequested) return;
      frameRequested = true;
      requestAnimationFrame(() => { frameRequested = false; draw(); });
    }
    function draw() {
      const offset = new THREE.Vector3(0.35, 0.45, 0).applyQuaternion(camera.quaternion)
                         .multiplyScalar(camera.position.distanceTo(controls.target));
      light.position.copy(camera.position).add(offset);
      light.target.position.copy(controls.target);
      renderer.render(scene, camera);
    }
    function resize() {
      const w = Math.max(1, viewEl.clientWidth), h = Math.max(1, viewEl.clientHeight);
      renderer.setSize(w, h);
      camera.aspect = w / h;
      camera.updateProjectionMatrix();
      requestFrame();
    }
    function setView(azimuth, elevation, zoom) {
      state.azimuth = azimuth; state.elevation = elevation; state.zoom = zoom || 1;
      const az = azimuth * Math.PI / 180, el = Math.max(-89.999, Math.min(89.999, elevation)) * Math.PI / 180;
      const fov = camera.fov * Math.PI / 180;
      const fovMin = Math.min(fov, 2 * Math.atan(Math.tan(fov / 2) * camera.aspect));
      const distance = radius / Math.sin(fovMin / 2) / state.zoom;
      const dir = new THREE.Vector3(Math.cos(el) * Math.sin(az), Math.sin(el), Math.cos(el) * Math.cos(az));
      camera.up.set(0, 1, 0);
      camera.position.copy(centre).addScaledVector(dir, distance);
      camera.near = Math.max(distance - 2 * radius, distance * 1e-3);
      camera.far = distance + 4 * radius;
      camera.updateProjectionMatrix();
      controls.target.copy(centre);
      controls.update();
      requestFrame();
    }

    // ---- Surfaces and colours ----
    function showSurface(name) {
      if (name === 'sculpt' && !sculptObject) name = 'displaced';
      if (!(name in surfaces) && name !== 'sculpt') name = 'displaced';
      state.surface = name;
      surfaceObject.visible = name !== 'sculpt';
      if (sculptObject) sculptObject.visible = name === 'sculpt';
      if (name !== 'sculpt') {
        const s = surfaces[name];
        if (!s.N) s.N = normalsOf(s.P);
        for (let k = 0; k < numSlots; ++k) {
          const g = 3 * gid[k];
          slotPos[3 * k] = s.P[g]; slotPos[3 * k + 1] = s.P[g + 1]; slotPos[3 * k + 2] = s.P[g + 2];
          slotNormal[3 * k] = s.N[g]; slotNormal[3 * k + 1] = s.N[g + 1]; slotNormal[3 * k + 2] = s.N[g + 2];
        }
        posAttr.needsUpdate = true;
        normalAttr.needsUpdate = true;
        geometry.computeBoundingSphere();
        geometry.computeBoundingBox();
      }
      updateOutline();
      syncControls();
      requestFrame();
    }
    function fillFace(f, c) {
      for (let k = slotStart[f]; k < slotStart[f + 1]; ++k) {
        slotColour[3 * k] = c[0]; slotColour[3 * k + 1] = c[1]; slotColour[3 * k + 2] = c[2];
      }
    }
    const legendEl = document.getElementById('legend');
    const colourNoteEl = document.getElementById('colour-note');
    const colourModes = {
      displacement: {
        label: 'displacement',
        available: true,
        apply() {
          for (let k = 0; k < numSlots; ++k) signedColour(value[gid[k]], valueRange, slotColour, 3 * k);
          const name = S.value_name === 'h' ? 'displacement h' : 'normal part D·N of the vector';
          const stops = [-1, -0.5, 0, 0.5, 1].map((t) => {
            const c = [0, 0, 0];
            signedColour(t * valueRange, valueRange, c, 0);
            return css(c) + ' ' + (50 + 50 * t) + '%';
          });
          legendEl.innerHTML = esc(name) + ' (the preview\'s colours: green +, red -)' +
              '<div class="bar" style="background: linear-gradient(to right, ' + stops.join(', ') +
              ')"></div>' + esc(fmt(-valueRange)) + ' &nbsp; 0 &nbsp; ' + esc(fmt(valueRange));
          return '';
        },
      },
      resolution: {
        label: 'resolution',
        available: !!ulog2,
        why: F.resolution_note,
        apply() {
          let lo = 99, hi = 0;
          const present = new Map();
          for (let f = 0; f < numFaces; ++f) {
            if (!quads[f] || constant[f]) continue;
            const l = ulog2[f] + vlog2[f];
            lo = Math.min(lo, l); hi = Math.max(hi, l);
          }
          for (let f = 0; f < numFaces; ++f) {
            if (!quads[f]) continue;
            let c = CONSTANT, key = 'constant';
            if (!constant[f]) {
              const l = ulog2[f] + vlog2[f];
              c = ramp(hi > lo ? (l - lo) / (hi - lo) : 1);
              key = (1 << l) + ' texels';
            }
            fillFace(f, c);
            const entry = present.get(key) || {colour: c, count: 0, order: constant[f] ? -1 : ulog2[f] + vlog2[f]};
            entry.count++;
            present.set(key, entry);
          }
          legendEl.innerHTML = 'each face\'s stored resolution<br>' + [...present.entries()]
              .sort((a, b) => a[1].order - b[1].order)
              .map(([k, e]) => '<span class="swatch" style="background:' + css(e.colour) + '"></span>' +
                   esc(k) + ' (' + e.count + ')').join(' ');
          return '';
        },
      },
      error: {
        label: 'verify error',
        available: !!faceError,
        why: data.verify ? F.error_note : 'no verify report: give dispex view --verify REPORT.json',
        apply() {
          const scale = tolerance > 0 ? tolerance : (errorMax > 0 ? errorMax / 2 : 1);
          for (let f = 0; f < numFaces; ++f) {
            if (!quads[f]) continue;
            const e = faceError[f];
            fillFace(f, isFinite(e) ? errorColour(e / scale) : UNKNOWN);
          }
          const unit = tolerance > 0 ? 'tolerances (' + fmt(tolerance) + ')' : 'of half the largest (' + fmt(scale) + ')';
          legendEl.innerHTML = 'verify error per face, ' + esc(errorName) + ', in ' + esc(unit) +
              '<div class="bar" style="background: linear-gradient(to right, ' + css(GREEN) + ', ' +
              css(YELLOW) + ', ' + css(RED) + ')"></div>0 &nbsp; 1 &nbsp; 2+' +
              '<span class="swatch" style="background:' + css(UNKNOWN) + '"></span>not measured';
          return F.error_note || '';
        },
      },
      holes: {
        label: 'holes filled',
        available: !!misses || withoutTile.size > 0,
        why: F.holes_note,
        apply() {
          let withMisses = 0, whole = 0;
          for (let f = 0; f < numFaces; ++f) {
            if (!quads[f]) continue;
            let c = NO_MISS;
            if ((allMissed && allMissed[f]) || withoutTile.has(f)) {
              c = ALL_MISSED; whole++;
            } else if (misses && misses[f] > 0) {
              const fraction = samples[f] > 0 ? misses[f] / samples[f] : 1;
              const t = Math.min(1, Math.log10(1 + 1000 * fraction) / 3);
              c = [0, 1, 2].map((k) => ORANGE[k] + t * (DEEP_RED[k] - ORANGE[k]));
              withMisses++;
            }
            fillFace(f, c);
          }
          legendEl.innerHTML = misses
              ? 'samples whose rays missed, filled<br><span class="swatch" style="background:' + css(NO_MISS) +
                '"></span>none<span class="swatch" style="background:' + css(ORANGE) + '"></span>a few' +
                '<span class="swatch" style="background:' + css(DEEP_RED) + '"></span>many (' + withMisses +
                ' faces)<span class="swatch" style="background:' + css(ALL_MISSED) +
                '"></span>every one: filled from the neighbours (' + whole + ')'
              : 'faces with points no UDIM tile holds<span class="swatch" style="background:' +
                css(ALL_MISSED) + '"></span>(' + whole + ')';
          return '';
        },
      },
      clay: {
        label: 'none',
        available: true,
        apply() {
          for (let f = 0; f < numFaces; ++f) fillFace(f, CLAY);
          legendEl.innerHTML = '';
          return '';
        },
      },
    };
    function showColour(name) {
      if (!colourModes[name] || !colourModes[name].available) name = 'displacement';
      state.colour = name;
      const note = colourModes[name].apply();
      colourAttr.needsUpdate = true;
      colourNoteEl.textContent = state.surface === 'sculpt'
          ? 'The sculpt is drawn in clay: colours are the map\'s.' : note;
      syncControls();
      requestFrame();
    }
    function setLit(lit) {
      state.lit = !!lit;
      surfaceObject.material = state.lit ? litMaterial : flatMaterial;
      if (sculptObject) sculptObject.material = state.lit ? sculptLit : sculptFlat;
      syncControls();
      requestFrame();
    }

    // ---- Picking ----
    const raycaster = new THREE.Raycaster();
    function faceOfTriangle(t) {
      let lo = 0, hi = numFaces;  // the last face whose first triangle is <= t
      while (hi - lo > 1) {
        const mid = (lo + hi) >> 1;
        if (triStart[mid] <= t) lo = mid; else hi = mid;
      }
      while (lo + 1 < numFaces && triStart[lo + 1] <= t) lo++;
      return lo;
    }
    function pickAt(clientX, clientY) {
      const rect = renderer.domElement.getBoundingClientRect();
      const ndc = new THREE.Vector2(((clientX - rect.left) / rect.width) * 2 - 1,
                                    -((clientY - rect.top) / rect.height) * 2 + 1);
      raycaster.setFromCamera(ndc, camera);
      if (state.surface === 'sculpt') {
        const hits = sculptObject ? raycaster.intersectObject(sculptObject) : [];
        selectFace(-1, hits.length ? 'The sculpt has no Ptex faces: pick on the map\'s surface.' : 'Nothing there.');
        return null;
      }
      const hits = raycaster.intersectObject(surfaceObject);
      if (!hits.length) { selectFace(-1, 'Nothing there.'); return null; }
      const face = faceOfTriangle(hits[0].faceIndex);
      selectFace(face);
      return faceInfo(face);
    }
    function faceInfo(f) {
      if (f < 0 || f >= numFaces) return null;
      const info = {face: f, base_face: baseFace[f], sub_face: subFace[f] === 255 ? null : subFace[f]};
      if (ulog2) {
        info.ures = 1 << ulog2[f]; info.vres = 1 << vlog2[f]; info.constant = !!constant[f];
      }
      let lo = Infinity, hi = -Infinity;
      for (let k = slotStart[f]; k < slotStart[f + 1]; ++k) {
        const v = value[gid[k]];
        lo = Math.min(lo, v); hi = Math.max(hi, v);
      }
      info.value_min = lo; info.value_max = hi;
      if (errorMapToSculpt) info.error_map_to_sculpt = errorMapToSculpt[f];
      if (errorTruth) info.error_truth = errorTruth[f];
      if (misses) {
        info.samples = samples[f]; info.misses = misses[f]; info.filled = filled[f];
        info.all_missed = !!allMissed[f];
      }
      info.discontinuous = discontinuous.has(f);
      if (F.without_tile) info.without_tile = withoutTile.has(f);
      return info;
    }
    const pickedEl = document.getElementById('picked');
    function inTolerances(e) {
      if (!isFinite(e)) return 'not measured';
      return fmt(e) + (tolerance > 0 ? ' (' + (e / tolerance).toFixed(2) + ' tolerances)' : '');
    }
    function selectFace(f, message) {
      state.face = f;
      const info = faceInfo(f);
      if (!info) {
        pickedEl.innerHTML = '<span class="note">' + esc(message || 'Click a face.') + '</span>';
      } else {
        const rows = [['face', 'face ' + f]];
        rows.push(['on the base', info.sub_face === null ? 'base face ' + info.base_face + ' (a quad)'
                   : 'base face ' + info.base_face + ', sub-face ' + info.sub_face + ' of the n-gon']);
        if (info.ures) {
          rows.push(['resolution', info.ures + ' x ' + info.vres + (info.constant ? ', stored constant' : '')]);
        }
        rows.push([S.value_name + ' on the page', fmt(info.value_min) + ' .. ' + fmt(info.value_max)]);
        if (errorMapToSculpt) rows.push(['error, map to sculpt', inTolerances(info.error_map_to_sculpt)]);
        if (errorTruth) rows.push(['error against the truth', inTolerances(info.error_truth)]);
        if (!errorMapToSculpt && !errorTruth) rows.push(['error', data.verify ? 'not in the verify report' : 'no verify report']);
        if (misses) {
          rows.push(['samples', info.samples]);
          rows.push(['holes', info.all_missed ? 'every ray missed: filled from the neighbours'
                              : info.misses + ' samples missed, ' + info.filled + ' filled']);
        } else {
          rows.push(['holes', F.holes_note || 'not recorded']);
        }
        if (info.discontinuous) rows.push(['edges', 'listed as discontinuous (not held watertight)']);
        if (info.without_tile) rows.push(['UV', 'points outside every UDIM tile (read as 0)']);
        pickedEl.innerHTML = table(rows);
      }
      updateOutline();
      requestFrame();
    }
    function updateOutline() {
      const f = state.face;
      if (f < 0 || state.surface === 'sculpt' || !quads[f]) { outline.visible = false; return; }
      const n = quads[f], s0 = slotStart[f], ring = [];
      for (let i = 0; i < n; ++i) ring.push(s0 + i);
      for (let j = 0; j < n; ++j) ring.push(s0 + j * (n + 1) + n);
      for (let i = n; i > 0; --i) ring.push(s0 + n * (n + 1) + i);
      for (let j = n; j > 0; --j) ring.push(s0 + j * (n + 1));
      const p = new Float32Array(3 * ring.length);
      ring.forEach((k, r) => { p[3 * r] = slotPos[3 * k]; p[3 * r + 1] = slotPos[3 * k + 1]; p[3 * r + 2] = slotPos[3 * k + 2]; });
      outline.geometry.dispose();
      outline.geometry = new THREE.BufferGeometry();
      outline.geometry.setAttribute('position', new THREE.BufferAttribute(p, 3));
      outline.visible = true;
    }
    let down = null;
    renderer.domElement.addEventListener('pointerdown', (e) => { down = [e.clientX, e.clientY]; });
    renderer.domElement.addEventListener('pointerup', (e) => {
      if (down && Math.hypot(e.clientX - down[0], e.clientY - down[1]) < 4) pickAt(e.clientX, e.clientY);
      down = null;
    });

    // ---- The panel ----
    const surfaceChoices = document.getElementById('surface-choices');
    const colourChoices = document.getElementById('colour-choices');
    function radio(container, group, value, label, enabled, title, onChange) {
      const l = document.createElement('label');
      const input = document.createElement('input');
      input.type = 'radio'; input.name = group; input.value = value; input.disabled = !enabled;
      input.addEventListener('change', () => onChange(value));
      l.appendChild(input);
      l.appendChild(document.createTextNode(' ' + label));
      if (!enabled) l.className = 'disabled';
      if (title) l.title = title;
      container.appendChild(l);
    }
    radio(surfaceChoices, 'surface', 'displaced', 'displaced', true, 'the limit surface displaced by the map', showSurface);
    radio(surfaceChoices, 'surface', 'limit', 'limit surface', true, 'the base\'s limit surface', showSurface);
    radio(surfaceChoices, 'surface', 'sculpt', 'sculpt', !!sculptObject,
          sculptObject ? 'the sculpt, decimated' : 'no sculpt: give dispex view --sculpt SCULPT', showSurface);
    for (const [name, mode] of Object.entries(colourModes)) {
      radio(colourChoices, 'colour', name, mode.label, mode.available, mode.available ? '' : mode.why, showColour);
    }
    const litEl = document.getElementById('lit');
    litEl.addEventListener('change', () => setLit(litEl.checked));
    document.getElementById('reset').addEventListener('click', () => setView(45, 35.26, 1));
    function syncControls() {
      for (const input of document.querySelectorAll('input[name=surface]')) input.checked = input.value === state.surface;
      for (const input of document.querySelectorAll('input[name=colour]')) input.checked = input.value === state.colour;
      litEl.checked = state.lit;
    }

    const M = data.map, meta = M.meta || {};
    const stats = meta['dispex:statistics'] || {};
    document.getElementById('map-info').innerHTML = table([
      ['map', data.inputs.map],
      ['kind', M.kind + (M.space ? ' (' + M.space + ' space)' : '')],
      ['base', data.inputs.base],
      ['sculpt', data.inputs.sculpt || meta['dispex:sculpt'] || '-'],
      ['Ptex faces', M.faces],
      M.channels !== undefined ? ['channels', M.channels] : null,
      M.data_type ? ['data type', M.data_type] : null,
      M.resolution ? ['tile resolution', M.resolution + ' x ' + M.resolution] : null,
      M.tiles ? ['UDIM tiles', M.tiles.map((t) => t.udim).join(', ')] : null,
      M.file_bytes ? ['file', fmt(M.file_bytes) + ' bytes'] : null,
      ['tolerance', M.tolerance],
      ['written by', meta['dispex:version'] ? 'dispex ' + meta['dispex:version'] : '-'],
    ]);
    const lod = data.lod;
    document.getElementById('lod-info').innerHTML = table([
      ['surface', fmt(S.vertices) + ' vertices, ' + fmt(S.triangles) + ' triangles'],
      ['grid', S.grid + ' x ' + S.grid + ' quads a quad face (' + S.grid / 2 + ' x ' + S.grid / 2 +
               ' an n-gon\'s sub-face), ' + (lod.grid_given ? 'given' : 'the finest within ' + fmt(lod.max_vertices) + ' vertices')],
      data.sculpt ? ['sculpt', fmt(data.sculpt.vertices) + ' vertices, ' + fmt(data.sculpt.triangles) +
                    ' triangles of ' + fmt(data.sculpt.vertices_read) + ' vertices, ' + fmt(data.sculpt.faces_read) +
                    ' faces' + (data.sculpt.cell > 0 ? ' (vertex clustering, cell ' + fmt(data.sculpt.cell) + ')' : ' (whole)')]
                  : ['sculpt', 'not on the page'],
    ]);
    document.getElementById('lodline').textContent =
        'surface ' + fmt(S.vertices) + ' vertices (grid ' + S.grid + ' a face)' +
        (data.sculpt ? ', sculpt ' + fmt(data.sculpt.vertices) + ' of ' + fmt(data.sculpt.vertices_read) + ' vertices' : '');

    // The extraction: the options and statistics the map records, the times its report holds.
    {
      let html = '';
      const texels = stats.texels || {};
      const rows = [
        ['method', stats.method],
        ['tolerance', stats.tolerance !== undefined ? fmt(stats.tolerance) + (stats.tolerance_auto ? ' (automatic)' : '') : undefined],
        ['search distance', stats.search_distance !== undefined ? fmt(stats.search_distance) + (stats.search_distance_auto ? ' (automatic)' : '') : undefined],
        ['samples', stats.samples],
        ['misses', stats.misses !== undefined ? fmt(stats.misses) + ' (' + fmt(100 * (stats.miss_fraction || 0), 3) + '%)' : undefined],
        ['holes filled', stats.holes_filled],
        ['faces with misses', stats.faces_with_misses],
        ['faces filled from neighbours', stats.faces_filled_from_neighbours],
        ['texels kept', texels.written !== undefined ? fmt(texels.written) + ' of ' + fmt(texels.oversampled) +
                        ' sampled (' + fmt(100 * texels.written_fraction, 3) + '%)' : undefined],
        ['constant faces', stats.spectral ? stats.spectral.constant_faces : undefined],
        ['displacement', stats.displacement ? fmt(stats.displacement.min) + ' .. ' + fmt(stats.displacement.max) +
                         ', rms ' + fmt(stats.displacement.rms) : undefined],
        ['watertight edges', stats.edges ? stats.edges.watertight : undefined],
      ];
      html += Object.keys(stats).length ? table(rows) : '<p class="note">The map records no statistics (not written by dispex extract).</p>';
      const R = data.extract_report;
      if (R) {
        const phases = Object.entries(R.phases_seconds || {}).sort((a, b) => b[1] - a[1]);
        html += '<h2>Times (' + esc(data.inputs.extract_report || 'the extraction\'s report') + ')</h2>' + table(
            [['total', (R.phases_seconds || {}).total, 3], ['threads', R.threads],
             ['peak memory', R.peak_rss_bytes ? fmt(R.peak_rss_bytes / 1e6, 4) + ' MB' : undefined]]
                .concat(phases.filter((p) => p[0] !== 'total').map((p) => [p[0] + ' (s)', p[1], 3])));
      } else {
        html += '<p class="note">Times are in the extraction\'s report, not in the map: give dispex view --extract-report REPORT.json.</p>';
      }
      if (meta['dispex:options']) html += rawJson('options', meta['dispex:options']);
      if (Object.keys(stats).length) html += rawJson('statistics', stats);
      const other = Object.assign({}, meta);
      delete other['dispex:options']; delete other['dispex:statistics'];
      html += rawJson('meta data', other);
      if (R) html += rawJson('extraction report', R);
      document.getElementById('report-info').innerHTML = html;
    }
    {
      const R = data.verify;
      let html;
      if (!R) {
        html = '<p class="note">No verify report: give dispex view --verify REPORT.json (dispex verify --report).</p>';
      } else {
        const d = (s) => s ? 'rms ' + fmt(s.rms) + ', p99 ' + fmt(s.p99) + ', max ' + fmt(s.max) : undefined;
        html = table([
          ['report', data.inputs.verify],
          ['result', R.passed ? 'passed' : 'FAILED: ' + (R.failure || '')],
          ['map to sculpt', d(R.map_to_sculpt)],
          ['sculpt to map', d(R.sculpt_to_map)],
          ['against the truth', R.truth ? d(R.truth) : undefined],
          ['edge steps, per face', R.edges ? d(R.edges.per_face) : undefined],
          ['edge steps, across faces', R.edges ? d(R.edges.across_faces) : undefined],
          ['per-face errors', faceError ? (F.error_note ? 'partial' : 'every face') : 'none'],
        ]) + (F.error_note ? '<p class="note">' + esc(F.error_note) + '</p>' : '') + rawJson('verify report', R);
      }
      document.getElementById('verify-info').innerHTML = html;
    }
    if (data.atlas) {
      const img = document.createElement('img');
      img.src = data.atlas;
      img.alt = 'the map\'s atlas (dispex preview)';
      document.getElementById('atlas').appendChild(img);
    } else {
      document.getElementById('atlas').innerHTML = '<p class="note">Not on the page (see the notes).</p>';
    }
    document.getElementById('notes').innerHTML =
        (data.notes.concat(data.warnings).map((n) => '<p class="note">' + esc(n) + '</p>').join('')) ||
        '<p class="note">None.</p>';
    document.getElementById('footer').textContent = 'Written by ' + data.generator +
        ' (dispex view); three.js r' + THREE.REVISION + '. Drag to turn, scroll to zoom, right-drag to pan.';

    // ---- Start ----
    function fromHash() {
      const h = new URLSearchParams(location.hash.replace(/^#/, ''));
      const num = (k, d) => (h.has(k) && isFinite(parseFloat(h.get(k))) ? parseFloat(h.get(k)) : d);
      setLit(h.has('lit') ? h.get('lit') !== '0' : state.lit);
      showSurface(h.get('surface') || state.surface);
      showColour(h.get('colour') || h.get('color') || state.colour);
      setView(num('azimuth', state.azimuth), num('elevation', state.elevation), num('zoom', state.zoom));
      if (h.has('face')) selectFace(Math.round(num('face', -1)));
    }
    controls.addEventListener('change', requestFrame);
    window.addEventListener('resize', resize);
    window.addEventListener('hashchange', fromHash);
    resize();
    fromHash();
    window.dispex = {
      setView, showSurface, showColour, setLit, pickAt, faceInfo, selectFace,
      state: () => Object.assign({}, state),
      canvasRect: () => renderer.domElement.getBoundingClientRect(),
    };
    draw();
    statusEl.textContent = '';
    requestAnimationFrame(() => requestAnimationFrame(() => { window.dispexReady = true; }));
  }

  try {
    main();
  } catch (e) {
    fail('The page could not be shown: ' + (e && e.message ? e.message : e));
    throw e;
  }
})();

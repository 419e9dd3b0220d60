// The 3D view of report.html (impeller-cam, src/view3d.rs): design part, tool paths per
// operation, the tool at the slider's move, the machined stock coloured by its deviation
// from the design, and the defects. three.js comes from the page itself (a text/plain
// script imported through a blob URL): no network.
//
// URL hash (for links and screenshots): #view3d (the view alone, full window), move=K
// (slider at global move K), at=NAME (slider at that operation's first feed move from its
// middle on),
// focus=overall|tool|op:NAME (its first feed move from the
// middle on, seen down the tool)|marker:N|marker:KIND (the first overcut/residual/collision marker), part=0|1,
// stock=0|1, shroud=0|1, links=0|1, upto=0|1 (paths up to the current move only).
// After its first frame the view sets on #view3d: data-drawn="1", data-frames,
// data-first-frame-ms (since navigation start), data-move, data-nonblank (fraction of
// sampled canvas pixels unlike the background), data-colours (distinct colours among them,
// 4 bits per channel); data-errors collects page errors and console.error messages.
(function () {
  'use strict';
  const root = document.getElementById('view3d');
  if (!root) return;
  const errors = [];
  function recordError(msg) {
    errors.push(String(msg));
    root.setAttribute('data-errors', errors.join(' | '));
  }
  window.addEventListener('error', (e) => recordError(e.message || e));
  window.addEventListener('unhandledrejection', (e) =>
    recordError((e.reason && (e.reason.stack || e.reason.message)) || e.reason));
  const consoleError = console.error.bind(console);
  console.error = (...a) => { recordError(a.join(' ')); consoleError(...a); };

  const params = {};
  const hash = location.hash.replace(/^#/, '');
  for (const kv of hash.split('&')) {
    const [k, v] = kv.split('=');
    if (k) params[k] = v === undefined ? '1' : decodeURIComponent(v);
  }
  if ('view3d' in params) document.body.classList.add('view3d-only');

  function bytes(s) {
    const bin = atob(s || '');
    const u = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) u[i] = bin.charCodeAt(i);
    return u.buffer;
  }

  async function main() {
    const data = JSON.parse(document.getElementById('view3d-data').textContent);
    if (data.empty) { root.setAttribute('data-drawn', 'empty'); return; }
    const jsBlob = (text) => URL.createObjectURL(new Blob([text], { type: 'text/javascript' }));
    const threeUrl = jsBlob(document.getElementById('three-module').textContent);
    const THREE = await import(threeUrl);
    const orbit = document.getElementById('three-orbit').textContent
      .replace(/from\s*['"]three['"]/g, 'from "' + threeUrl + '"');
    const { OrbitControls } = await import(jsBlob(orbit));

    const origin = data.origin, step = data.step;
    // State read by the functions below (declared first: toggles call them at once).
    let current = 0, frames = 0, pending = false, clearPixel = null;
    // Positions relative to the scene centre keep float32 precise.
    const centre = [0, 0, 0];
    function positions(b64) {
      const q = new Uint16Array(bytes(b64));
      const f = new Float32Array(q.length);
      for (let i = 0; i < q.length; i++) f[i] = origin[i % 3] + q[i] * step - centre[i % 3];
      return f;
    }
    // Scene centre: middle of the quantisation grid's box.
    for (let k = 0; k < 3; k++) centre[k] = origin[k] + 32767.5 * step;

    const container = document.getElementById('view3d-canvas');
    const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    const background = new THREE.Color(0xf7f7f7);
    renderer.setClearColor(background, 1);
    container.appendChild(renderer.domElement);
    const scene = new THREE.Scene();
    const camera = new THREE.PerspectiveCamera(35, 1, 0.05, 5000);
    camera.up.set(0, 0, 1);
    scene.add(new THREE.HemisphereLight(0xffffff, 0x445566, 1.6));
    const sun = new THREE.DirectionalLight(0xffffff, 1.6);
    sun.position.set(1, -1, 2);
    camera.add(sun);
    scene.add(camera);
    const controls = new OrbitControls(camera, renderer.domElement);

    const panel = document.getElementById('view3d-panel');
    function toggle(label, on, set) {
      const l = document.createElement('label');
      const c = document.createElement('input');
      c.type = 'checkbox'; c.checked = on;
      c.addEventListener('change', () => { set(c.checked); redraw(); });
      l.appendChild(c); l.appendChild(document.createTextNode(' ' + label));
      panel.appendChild(l);
      set(on);
      return c;
    }
    function heading(text) {
      const h = document.createElement('div');
      h.style.fontWeight = 'bold'; h.style.marginTop = '6px'; h.textContent = text;
      panel.appendChild(h);
    }
    const flag = (k, dflt) => (k in params ? params[k] !== '0' : dflt);

    // Design part.
    const box = new THREE.Box3();
    let part = null;
    if (data.part && data.part.triangles > 0) {
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(positions(data.part.positions), 3));
      g.setIndex(new THREE.BufferAttribute(new Uint32Array(bytes(data.part.indices)), 1));
      g.computeVertexNormals();
      g.computeBoundingBox();
      box.union(g.boundingBox);
      part = new THREE.Mesh(g, new THREE.MeshStandardMaterial({
        color: 0xb8c0c8, metalness: 0.2, roughness: 0.55, side: THREE.DoubleSide,
        polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 }));
      scene.add(part);
    }
    const shroudPos = positions(data.shroud);
    let shroud = null;
    if (shroudPos.length) {
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(shroudPos, 3));
      shroud = new THREE.LineSegments(g, new THREE.LineBasicMaterial({
        color: 0x777777, transparent: true, opacity: 0.5 }));
      scene.add(shroud);
    }

    // Machined stock coloured by deviation.
    const st = data.stock;
    const neutral = [0.78, 0.78, 0.74];
    function colourOf(um) {
      if (um === -32768) return neutral;
      const d = um / 1000;
      const tol = st.machining_tol_mm;
      if (d < -st.overcut_limit_mm) return [0.85, 0.05, 0.05];
      if (d < -tol) return [1.0, 0.6, 0.1];
      if (d <= tol) return [0.2, 0.72, 0.3];
      const rmax = Math.max(st.residual_max_mm, 2 * tol, 1e-3);
      const t = Math.min((d - tol) / (rmax - tol), 1);
      // green (on size) -> cyan -> blue (most material left)
      const a = [0.2, 0.72, 0.3], b = [0.2, 0.7, 0.85], c = [0.15, 0.2, 0.75];
      const mix = (p, q, s) => [0, 1, 2].map((k) => p[k] + (q[k] - p[k]) * s);
      return t < 0.5 ? mix(a, b, 2 * t) : mix(b, c, 2 * t - 1);
    }
    let stock = null;
    if (st) {
      const g = new THREE.BufferGeometry();
      const pos = positions(st.positions);
      const dev = new Int16Array(bytes(st.deviation_um));
      const col = new Float32Array(pos.length);
      for (let i = 0; i < dev.length; i++) col.set(colourOf(dev[i]), 3 * i);
      g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
      g.setAttribute('color', new THREE.BufferAttribute(col, 3));
      g.setIndex(new THREE.BufferAttribute(new Uint32Array(bytes(st.indices)), 1));
      g.computeVertexNormals();
      g.computeBoundingBox();
      box.union(g.boundingBox);
      stock = new THREE.Mesh(g, new THREE.MeshLambertMaterial({
        vertexColors: true, side: THREE.DoubleSide }));
      scene.add(stock);
    }

    // Tool paths: cutting moves in the operation's colour, links and rapids grey.
    const ops = [];
    for (const op of data.operations) {
      const tips = positions(op.tips);
      const kinds = new Uint8Array(bytes(op.kinds));
      const ax = new Int16Array(bytes(op.axes));
      const n = op.moves;
      const cut = [], link = [];
      const cutUpTo = new Int32Array(n), linkUpTo = new Int32Array(n);
      for (let i = 1; i < n; i++) {
        const seg = kinds[i] === 1 || kinds[i] === 2 ? cut : link;
        for (const j of [i - 1, i]) seg.push(tips[3 * j], tips[3 * j + 1], tips[3 * j + 2]);
        cutUpTo[i] = cut.length / 6; linkUpTo[i] = link.length / 6;
      }
      const lines = (arr, material) => {
        const g = new THREE.BufferGeometry();
        g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(arr), 3));
        const l = new THREE.LineSegments(g, material);
        scene.add(l);
        return l;
      };
      const cutLines = lines(cut, new THREE.LineBasicMaterial({ color: op.colour }));
      const linkLines = lines(link, new THREE.LineBasicMaterial({
        color: 0x999999, transparent: true, opacity: 0.35 }));
      if (cut.length) { cutLines.geometry.computeBoundingBox(); box.union(cutLines.geometry.boundingBox); }
      // The tool: cutter, shank and holder revolved about +Y, turned onto the axis.
      const tool = new THREE.Group();
      if (op.profile) {
        const parts = [['cutter', 0xd4a017], ['shank', 0x8a8f96], ['holder', 0x4a5058]];
        for (const [key, colour] of parts) {
          const pts = op.profile[key];
          if (!pts || pts.length < 2) continue;
          const v = pts.map(([r, h]) => new THREE.Vector2(Math.max(r, 1e-4), h));
          if (key !== 'cutter') {
            v.unshift(new THREE.Vector2(1e-4, pts[0][1]));
            v.push(new THREE.Vector2(1e-4, pts[pts.length - 1][1]));
          }
          tool.add(new THREE.Mesh(new THREE.LatheGeometry(v, 32),
            new THREE.MeshStandardMaterial({ color: colour, metalness: 0.5, roughness: 0.4 })));
        }
      }
      tool.visible = false;
      scene.add(tool);
      ops.push({ op, tips, kinds, ax, n, cutLines, linkLines, cutUpTo, linkUpTo, tool, shown: true });
    }
    const total = data.moves;

    // Panel: layers, operations, colour bar, defects.
    heading('Layers');
    if (part) toggle('design part (hub, blades)', flag('part', !stock), (on) => { part.visible = on; });
    if (shroud) toggle('shroud contour', flag('shroud', true), (on) => { shroud.visible = on; });
    if (stock) toggle('machined stock (verification)', flag('stock', true), (on) => { stock.visible = on; });
    let showLinks = true, upToMove = false;
    toggle('links and rapids', flag('links', true), (on) => { showLinks = on; applyPaths(); });
    toggle('paths up to the current move only', flag('upto', false), (on) => { upToMove = on; applyPaths(); });
    heading('Operations (cutting moves)');
    for (const o of ops) {
      const swatch = '\u25a0 ';
      const c = toggle(swatch + o.op.name + ' (' + o.op.kind.replace(/_/g, ' ') + ', ' + o.op.tool + ', ' +
        o.n.toLocaleString('en') + ' moves)', true, (on) => { o.shown = on; applyPaths(); });
      c.parentNode.style.color = o.op.colour;
    }
    if (st) {
      heading('Stock deviation from the design (mm)');
      const cv = document.createElement('canvas');
      cv.width = 260; cv.height = 14; cv.style.border = '1px solid #999';
      panel.appendChild(cv);
      const lo = -1.5 * st.overcut_limit_mm;
      const hi = Math.max(st.residual_max_mm, 2 * st.machining_tol_mm, 1e-3);
      const cx = cv.getContext('2d');
      for (let x = 0; x < cv.width; x++) {
        const d = lo + (hi - lo) * (x + 0.5) / cv.width;
        const c = colourOf(Math.round(d * 1000));
        cx.fillStyle = 'rgb(' + c.map((v) => Math.round(255 * v)).join(',') + ')';
        cx.fillRect(x, 0, 1, cv.height);
      }
      const ticks = document.createElement('div');
      ticks.style.position = 'relative'; ticks.style.height = '28px'; ticks.style.width = '262px';
      const at = (d, text, row) => {
        const s = document.createElement('span');
        s.style.position = 'absolute'; s.style.top = (row ? 13 : 0) + 'px'; s.style.whiteSpace = 'nowrap';
        s.style.fontSize = '10px';
        s.style.left = Math.round(260 * (d - lo) / (hi - lo)) + 'px';
        s.style.transform = 'translateX(-50%)';
        s.textContent = '|' + text;
        ticks.appendChild(s);
      };
      at(-st.overcut_limit_mm, '\u2212' + st.overcut_limit_mm.toFixed(3));
      at(st.machining_tol_mm, '\u00b1' + st.machining_tol_mm, 1);
      at(hi, hi.toFixed(2));
      at(hi / 2, (hi / 2).toFixed(2));
      panel.appendChild(ticks);
      const legend = document.createElement('div');
      legend.innerHTML = '<span style="color:#d90d0d">\u25a0</span> overcut beyond the limit ' +
        st.overcut_limit_mm.toFixed(4) + ' mm (machining_tol ' + st.machining_tol_mm +
        ' + simulation bound); <span style="color:#ff9919">\u25a0</span> overcut beyond ' +
        'machining_tol, within the limit; <span style="color:#38b84d">\u25a0</span> within \u00b1' +
        st.machining_tol_mm + ' mm; cyan \u2192 blue: residual up to ' + hi.toFixed(3) +
        ' mm; grey: away from the design. ' +
        'Stock lattice ' + st.spacing_mm + ' mm (dexels ' + st.resolution_mm + ' mm).';
      panel.appendChild(legend);
    }
    const markers = [];
    if (data.markers.length) {
      heading('Defects and extremes');
      const list = document.createElement('ol');
      list.style.paddingLeft = '18px';
      panel.appendChild(list);
      // Unit spheres scaled before each frame to about 7 px radius (see redraw).
      const size = 1;
      const colours = { overcut: 0xd90d0d, residual: 0x2040c0, collision: 0x9900cc };
      data.markers.forEach((m, k) => {
        const p = new THREE.Vector3(m.point[0] - centre[0], m.point[1] - centre[1], m.point[2] - centre[2]);
        const s = new THREE.Mesh(new THREE.SphereGeometry(size, 16, 12),
          new THREE.MeshBasicMaterial({ color: colours[m.kind] || 0x000000, depthTest: false }));
        s.renderOrder = 10;
        s.position.copy(p);
        s.userData.marker = k;
        scene.add(s);
        markers.push({ m, p, mesh: s });
        const li = document.createElement('li');
        li.textContent = m.label + (m.move !== null ? ' \u2192 move ' + m.move +
          ' (tool ' + m.distance_mm.toFixed(3) + ' mm away)' : '');
        li.addEventListener('click', () => goToMarker(k));
        list.appendChild(li);
      });
    }

    const slider = document.getElementById('view3d-slider');
    const label = document.getElementById('view3d-move');
    slider.max = String(Math.max(total - 1, 0));
    const kindNames = ['rapid', 'plunge', 'feed', 'retract'];
    function opOf(g) {
      for (const o of ops) if (g < o.op.first_move + o.n) return o;
      return ops[ops.length - 1];
    }
    function applyPaths() {
      for (const o of ops) {
        const local = current - o.op.first_move;
        const full = !upToMove || local >= o.n;
        const before = upToMove && local < 0;
        o.cutLines.visible = o.shown && !before;
        o.linkLines.visible = o.shown && showLinks && !before;
        const i = Math.min(Math.max(local, 0), o.n - 1);
        o.cutLines.geometry.setDrawRange(0, full ? Infinity : 2 * o.cutUpTo[i]);
        o.linkLines.geometry.setDrawRange(0, full ? Infinity : 2 * o.linkUpTo[i]);
      }
      redraw();
    }
    const yAxis = new THREE.Vector3(0, 1, 0);
    function setMove(g) {
      if (!ops.length) return;
      current = Math.min(Math.max(Math.round(g), 0), Math.max(total - 1, 0));
      slider.value = String(current);
      const o = opOf(current);
      const i = current - o.op.first_move;
      for (const q of ops) q.tool.visible = q === o;
      o.tool.position.set(o.tips[3 * i], o.tips[3 * i + 1], o.tips[3 * i + 2]);
      const a = new THREE.Vector3(o.ax[3 * i], o.ax[3 * i + 1], o.ax[3 * i + 2]).normalize();
      o.tool.quaternion.setFromUnitVectors(yAxis, a);
      const tip = [0, 1, 2].map((k) => (o.tips[3 * i + k] + centre[k]).toFixed(3));
      label.textContent = 'move ' + current.toLocaleString('en') + ' / ' + total.toLocaleString('en') +
        ': ' + o.op.name + ' #' + i + ' (' + kindNames[o.kinds[i]] + '), tip (' + tip.join(', ') + ') mm';
      root.setAttribute('data-move', String(current));
      applyPaths();
    }
    slider.addEventListener('input', () => setMove(Number(slider.value)));
    let playing = null;
    document.getElementById('view3d-play').addEventListener('click', (e) => {
      if (playing) { clearInterval(playing); playing = null; e.target.textContent = 'play'; return; }
      e.target.textContent = 'pause';
      const inc = Math.max(1, Math.round(total / 1200));
      playing = setInterval(() => {
        if (current + inc >= total) { clearInterval(playing); playing = null; e.target.textContent = 'play'; }
        setMove(current + inc);
      }, 16);
    });

    function look(target, distance, dir) {
      const d = (dir || new THREE.Vector3(1, -1.3, 1)).clone().normalize();
      controls.target.copy(target);
      camera.position.copy(target).addScaledVector(d, distance);
      camera.near = Math.max(distance / 1000, 0.01);
      camera.far = distance * 100;
      camera.updateProjectionMatrix();
      controls.update();
      redraw();
    }
    function overall() {
      const c = box.isEmpty() ? new THREE.Vector3() : box.getCenter(new THREE.Vector3());
      const r = box.isEmpty() ? 50 : box.getSize(new THREE.Vector3()).length() / 2;
      look(c, 1.05 * r / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2)));
    }
    function goToMarker(k) {
      const mk = markers[k];
      if (!mk) return;
      if (mk.m.move === null) { look(mk.p, 25); return; }
      setMove(mk.m.move);
      viewAlong(mk.p, axisAt(mk.m.move));
    }
    function axisAt(g) {
      const o = opOf(g);
      const i = g - o.op.first_move;
      return new THREE.Vector3(o.ax[3 * i], o.ax[3 * i + 1], o.ax[3 * i + 2]).normalize();
    }
    // Looks at `target` down the tool axis `a`, 25 degrees off it (the tool reached there, so
    // the line of sight along it is mostly clear), 18 mm away (below a holder), from the
    // first of eight sides around the axis whose line of sight no visible surface blocks.
    function viewAlong(target, a) {
      const side = new THREE.Vector3().crossVectors(a, new THREE.Vector3(0, 0, 1));
      if (side.lengthSq() < 1e-6) side.set(1, 0, 0);
      side.normalize();
      const off = THREE.MathUtils.degToRad(25), distance = 18;
      const solids = [part, stock].filter((m) => m && m.visible);
      const ray = new THREE.Raycaster();
      const at = (k) => a.clone().multiplyScalar(Math.cos(off))
        .addScaledVector(side.clone().applyAxisAngle(a, k * Math.PI / 4), Math.sin(off));
      let dir = null;
      for (let k = 0; k < 8 && !dir; k++) {
        const d = at(k);
        ray.set(target.clone().addScaledVector(d, 0.5), d);
        ray.far = distance;
        if (!ray.intersectObjects(solids).length) dir = d;
      }
      look(target, distance, dir || at(0));
    }
    function focusTool() {
      const o = opOf(current);
      const i = current - o.op.first_move;
      viewAlong(new THREE.Vector3(o.tips[3 * i], o.tips[3 * i + 1], o.tips[3 * i + 2]), axisAt(current));
    }
    renderer.domElement.addEventListener('click', (e) => {
      const r = renderer.domElement.getBoundingClientRect();
      const ray = new THREE.Raycaster();
      ray.setFromCamera(new THREE.Vector2(((e.clientX - r.left) / r.width) * 2 - 1,
        -((e.clientY - r.top) / r.height) * 2 + 1), camera);
      const hit = ray.intersectObjects(markers.map((m) => m.mesh))[0];
      if (hit) goToMarker(hit.object.userData.marker);
    });

    function resize() {
      const w = container.clientWidth || 800, h = container.clientHeight || 600;
      renderer.setSize(w, h);
      camera.aspect = w / h;
      camera.updateProjectionMatrix();
      redraw();
    }
    function redraw() {
      if (pending) return;
      pending = true;
      requestAnimationFrame(() => {
        pending = false;
        if (!clearPixel) {
          // The background as the canvas holds it (after colour management).
          renderer.clear();
          const gl = renderer.getContext();
          const p = new Uint8Array(4);
          gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, p);
          clearPixel = [p[0], p[1], p[2]];
        }
        const pxAngle = THREE.MathUtils.degToRad(camera.fov) / Math.max(container.clientHeight, 1);
        for (const mk of markers) {
          mk.mesh.scale.setScalar(7 * pxAngle * camera.position.distanceTo(mk.p));
        }
        renderer.render(scene, camera);
        frames++;
        root.setAttribute('data-frames', String(frames));
        if (frames === 1) firstFrame();
      });
    }
    function firstFrame() {
      root.setAttribute('data-first-frame-ms', String(Math.round(performance.now())));
      const gl = renderer.getContext();
      const bg = clearPixel;
      const w = gl.drawingBufferWidth, h = gl.drawingBufferHeight;
      const px = new Uint8Array(w * h * 4);
      gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
      let sampled = 0, differ = 0;
      const colours = new Set();
      for (let y = 0; y < h; y += 3) {
        for (let x = 0; x < w; x += 3) {
          const o = 4 * (y * w + x);
          sampled++;
          const d = Math.abs(px[o] - bg[0]) + Math.abs(px[o + 1] - bg[1]) + Math.abs(px[o + 2] - bg[2]);
          if (d > 24) differ++;
          colours.add((px[o] >> 4) << 8 | (px[o + 1] >> 4) << 4 | px[o + 2] >> 4);
        }
      }
      root.setAttribute('data-nonblank', (sampled ? differ / sampled : 0).toFixed(4));
      root.setAttribute('data-colours', String(colours.size));
      root.setAttribute('data-drawn', '1');
    }
    controls.addEventListener('change', redraw);
    if (window.ResizeObserver) new ResizeObserver(resize).observe(container);
    resize();
    overall();
    const atOp = params.at !== undefined ? ops.find((q) => q.op.name === params.at) : undefined;
    if (params.move !== undefined) setMove(Number(params.move));
    else if (atOp) {
      // The first feed move from the operation's middle on.
      let i = Math.floor(atOp.n / 2);
      while (i + 1 < atOp.n && atOp.kinds[i] !== 2) i++;
      setMove(atOp.op.first_move + i);
    }
    else setMove(0);
    const focus = params.focus || 'overall';
    if (focus === 'tool') focusTool();
    else if (focus.startsWith('op:')) {
      // The middle move of the named operation, seen beside the tool.
      const o = ops.find((q) => q.op.name === focus.slice(3));
      if (o && params.move === undefined) {
        let i = Math.floor(o.n / 2);
        while (i + 1 < o.n && o.kinds[i] !== 2) i++;
        setMove(o.op.first_move + i);
      }
      focusTool();
    } else if (focus.startsWith('marker:')) {
      const key = focus.slice(7);
      const k = /^[0-9]+$/.test(key) ? Number(key) : data.markers.findIndex((m) => m.kind === key);
      goToMarker(k);
    }
    redraw();
  }
  main().catch((e) => recordError((e && (e.stack || e.message)) || e));
})();

// ros-tank-tutorial: a live meshcat view over the notebook's own connection (tutorial/view/widget/).
//
// Each view is an <iframe srcdoc> holding meshcat's own page: meshcat's viewer script (sent once per
// browser page by the kernel, gzip-compressed) and the project's page script (PAGE_SCRIPT: set_transforms,
// lighter drawing without a GPU).  The kernel sends meshcat's own commands, packed with msgpack, as the
// buffers of one widget message a frame.  The view answers the frames it has drawn with "drawn" (how
// many), which is what lets the kernel send the next: a slow browser gets fewer frames, never a queue.
// It answers four frames at a time (ANSWER_EVERY), or what it owes 0.25 s after the first of them was
// drawn (LONE_WAIT_MS): the kernel publishes a busy and an idle status for every message it is sent, and
// the Jupyter server relays each of them, so an answer per frame would double the traffic on the kernel's
// connection and slow the frames themselves (the Benchmarks page, "Live views in the notebook").  At a
// class server's 20 frames/s a view answers five times a second, not twenty; the kernel keeps eight
// frames in flight, so waiting holds no frame back.
// A view that opens (a page reload, a second tab) says "hello" and is sent the whole scene.
//
// A message the view cannot take (not a meshcat command, a buffer over the limit, a set_transforms to a
// path the scene does not have, a number that is not finite) is named in the console, and that frame is
// dropped whole; the view goes on with the next.
const PAGE_SCRIPT = __PAGE_SCRIPT__;
const LIMITS = __LIMITS__;
const KNOWN = ["set_transform", "set_transforms", "set_object", "set_property", "delete", "set_animation"];
const SCRIPT_KEY = "__rttMeshcatViewerScript";
const ANSWER_EVERY = __ANSWER_EVERY__;  // frames drawn that are answered at once: half flow.py's WINDOW (widget.py)
const LONE_WAIT_MS = __LONE_WAIT_MS__;  // how long the first frame owed waits for the others before it is answered, ms

// meshcat's viewer script as a blob: URL, asked of the kernel once per browser page and shared by every view.
function viewerScript(model) {
  let promise = globalThis[SCRIPT_KEY];
  if (!promise) {
    promise = new Promise((resolve, reject) => {
      const take = async (msg, buffers) => {
        if (!msg || msg.type !== "viewer_js") return;
        clearTimeout(timer);
        model.off("msg:custom", take);
        try {
          const stream = new Blob([buffers[0]]).stream().pipeThrough(new DecompressionStream("gzip"));
          const text = await new Response(stream).blob();
          resolve(URL.createObjectURL(new Blob([text], { type: "text/javascript" })));
        } catch (error) {
          reject(error);
        }
      };
      const timer = setTimeout(() => {
        model.off("msg:custom", take);
        reject(new Error("the kernel did not send meshcat's viewer script within 60 s (is it busy?)"));
      }, 60000);
      model.on("msg:custom", take);
      model.send({ type: "viewer_js" });
    });
    globalThis[SCRIPT_KEY] = promise;
    promise.catch(() => {
      if (globalThis[SCRIPT_KEY] === promise) delete globalThis[SCRIPT_KEY];  // the next view asks again
    });
  }
  return promise;
}

function page(scriptUrl) {
  const tail = "</" + "script>";
  return (
    '<!DOCTYPE html><html><head><meta charset="utf-8"><style>body { margin: 0; } ' +
    "#meshcat-pane { width: 100vw; height: 100vh; overflow: hidden; }</style></head><body>" +
    '<div id="meshcat-pane"></div><script src="' + scriptUrl + '">' + tail +
    '<script>var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));\n' +
    PAGE_SCRIPT + tail + "</body></html>"
  );
}

// One packed command, decoded by meshcat's own msgpack decoder (its handler, caught before it runs).
function decode(viewer, bytes) {
  let out;
  const handle = viewer.handle_command;
  viewer.handle_command = (cmd) => {
    out = cmd;
  };
  try {
    viewer.handle_command_bytearray(bytes);
  } finally {
    viewer.handle_command = handle;
  }
  return out;
}

function pathParts(path) {
  return path.split("/").filter((p) => p.length > 0);
}

function hasNode(viewer, path) {
  let node = viewer.scene_tree;
  for (const part of pathParts(path)) {
    node = node.children[part];
    if (!node) return false;
  }
  return true;
}

function checkTransform(cmd, viewer, created) {
  const m = cmd.matrix;
  if (!m || m.length !== 16) throw new Error(`set_transform at ${cmd.path}: the matrix is not 16 numbers`);
  for (let i = 0; i < 16; i++) {
    if (typeof m[i] !== "number" || !Number.isFinite(m[i])) {
      throw new Error(`set_transform at ${cmd.path}: matrix entry ${i} is ${m[i]}, not a finite number`);
    }
  }
  // A frame's transforms move what the scene has (or what the same message draws first): a path it does
  // not have is an error, not a new node.
  if (created && !created.has(pathParts(cmd.path).join("/")) && !hasNode(viewer, cmd.path)) {
    throw new Error(`set_transforms: no ${cmd.path} in the scene`);
  }
}

// One packed command, decoded and checked; throws an Error naming what is wrong.  ``created``: the paths
// (and their parents) that set_object commands earlier in the same message draw.
function checkOne(viewer, buffer, created) {
  if (buffer.byteLength > LIMITS.max_command_bytes) {
    throw new Error(`a command of ${buffer.byteLength} bytes, over the limit of ${LIMITS.max_command_bytes}`);
  }
  let cmd;
  try {
    cmd = decode(viewer, new Uint8Array(buffer.buffer, buffer.byteOffset, buffer.byteLength));
  } catch (error) {
    throw new Error(`a command that is not msgpack: ${error.message}`);
  }
  if (!cmd || typeof cmd !== "object" || !KNOWN.includes(cmd.type)) {
    throw new Error(`not a meshcat scene command: type ${cmd && cmd.type}`);
  }
  if (cmd.type !== "set_animation" && cmd.type !== "set_transforms") {  // those two have no path of their own
    if (typeof cmd.path !== "string" || cmd.path.length > LIMITS.max_path_chars) {
      throw new Error(`${cmd.type}: the path is not a string of at most ${LIMITS.max_path_chars} characters`);
    }
    if (pathParts(cmd.path).length > LIMITS.max_path_parts) {
      throw new Error(`${cmd.type}: a path of more than ${LIMITS.max_path_parts} parts`);
    }
  }
  if (cmd.type === "set_transform") checkTransform(cmd, viewer, null);
  if (cmd.type === "set_transforms") {
    if (!Array.isArray(cmd.commands) || cmd.commands.length > LIMITS.max_commands) {
      throw new Error(`set_transforms: not a list of at most ${LIMITS.max_commands} commands`);
    }
    for (const inner of cmd.commands) {
      if (!inner || inner.type !== "set_transform" || typeof inner.path !== "string") {
        throw new Error("set_transforms: an entry that is not a set_transform with a path");
      }
      checkTransform(inner, viewer, created);
    }
  }
  if (cmd.type === "set_object") {
    const parts = pathParts(cmd.path);
    for (let n = 1; n <= parts.length; n++) created.add(parts.slice(0, n).join("/"));
  }
  return cmd;
}

// The commands of one message, each checked: [good commands, errors].
function check(viewer, buffers) {
  const commands = [];
  const errors = [];
  const created = new Set();
  for (const buffer of buffers) {
    try {
      commands.push(checkOne(viewer, buffer, created));
    } catch (error) {
      errors.push(error.message);
    }
  }
  return [commands, errors];
}

function render({ model, el }) {
  const id = Math.random().toString(36).slice(2);
  const label = model.get("label");
  const frame = document.createElement("iframe");
  frame.style.cssText = `width: 100%; height: ${model.get("height")}px; border: none; display: block`;
  frame.title = label;
  frame.className = "rtt-live-view";
  el.appendChild(frame);
  // Under the view: what it shows now (the widget's status, set by the kernel), or that it is not live.
  const caption = document.createElement("div");
  caption.className = "rtt-caption";
  caption.style.cssText = "font-size: 90%; margin-top: 2px";
  el.appendChild(caption);
  const showCaption = (live) => {
    const status = model.get("status");
    caption.innerHTML = "";
    const name = document.createElement("b");
    name.textContent = label;
    caption.appendChild(name);
    caption.appendChild(document.createTextNode(
      live ? ` (live)${status ? ": " + status : ""}`
        : " (not live): its kernel has gone, so nothing runs; run the section again for a live view."));
  };
  showCaption(true);
  const onStatus = () => {
    if (!notice) showCaption(true);
  };
  model.on("change:status", onStatus);
  // What the view has done, for a test or a curious learner: el.rttView in the browser's console.
  const stats = { id, frames: 0, dropped: 0, scenes: 0, errors: [] };
  el.rttView = stats;
  let viewer = null;
  let gone = false;
  let notice = null;  // the "not live any more" notice, while it shows

  // A benchmark's probe (benchmarks/experiments/widget.py sets window.rttProbe to an array): for each
  // frame, [its number, when it arrived, when it was drawn], on this page's clock, ms.
  const now = () => performance.timeOrigin + performance.now();
  let owed = 0;  // frames drawn and not answered yet: fewer than ANSWER_EVERY, for about LONE_WAIT_MS at most
  let answered = 0;  // answers sent: a wait for owed frames that an answer overtook ends without answering
  const settle = () => {
    try {
      if (!gone && owed > 0) model.send({ type: "drawn", frames: owed });
    } catch (error) {
      // cut off its kernel (restarted): nothing to answer; the comm_live_update watch says so
    }
    owed = 0;
    answered += 1;
  };
  const answer = (n) => {
    const probe = Array.isArray(window.rttProbe) && n !== undefined ? [n, now(), null] : null;
    if (probe) window.rttProbe.push(probe);
    // Once the frame after this message has been drawn: meshcat draws in its animation frame, which it
    // asked for before this one, so it runs first.
    const view = frame.contentWindow;
    view.requestAnimationFrame(() => {
      if (probe) probe[2] = now();
      owed += 1;
      if (owed >= ANSWER_EVERY) {
        settle();
      } else if (owed === 1) {  // the first owed: answered with the others, or LONE_WAIT_MS from now (in an
        // animation frame, so a hidden tab answers nothing, whatever its display's refresh rate)
        const drawnAt = performance.now();
        const since = answered;
        const wait = () => {
          if (answered !== since) return;  // answered meanwhile, with the others
          if (performance.now() - drawnAt >= LONE_WAIT_MS) settle();
          else view.requestAnimationFrame(wait);
        };
        view.requestAnimationFrame(wait);
      }
    });
  };
  let resynced = 0;  // when this view last asked for the whole scene after a dropped frame, ms
  const say = (error) => {
    stats.errors.push(error);
    if (stats.errors.length > 20) stats.errors.shift();
    console.error(`ros-tank-tutorial view "${label}": ${error}`);
    model.send({ type: "rejected", reason: String(error).slice(0, 300) });
  };
  const onMessage = (msg, buffers) => {
    if (msg && msg.type === "pong") {
      stats.ponged = Date.now();
      if (notice) {
        notice.remove();
        notice = null;
        showCaption(true);
      }
      return;
    }
    if (!viewer || !msg) return;
    if (msg.type !== "frame" && !(msg.type === "scene" && msg.to === id)) return;
    const [commands, errors] = check(viewer, buffers || []);
    if (msg.type === "frame" && errors.length > 0) {
      // A frame is drawn whole or not at all; what it would have changed comes back with the whole scene,
      // asked for again (at most every 2 s, so a sender of bad frames cannot make it ask all the time).
      stats.dropped += 1;
      say(`dropped a frame: ${errors[0]}`);
      if (Date.now() - resynced > 2000) {
        resynced = Date.now();
        model.send({ type: "hello", id });
      }
      answer();
      return;
    }
    // The whole scene: every command it can take is drawn, each one it cannot is named.
    for (const error of errors) say(`left out of the scene: ${error}`);
    for (const cmd of commands) viewer.handle_command(cmd);
    if (msg.type === "scene") stats.scenes += 1;
    stats.frames += 1;
    answer(msg.n);
  };
  model.on("msg:custom", onMessage);
  // JupyterLab's widget manager cuts every widget off its kernel when the kernel restarts or stops,
  // and says so to each model (comm_live_update).  The view then asks its kernel whether it is still
  // there: no answer within PING_MS, and the page says this view is not live any more (its last frame
  // stays).  An answer that comes later (a kernel that was only busy) takes the notice away.
  const onCutOff = () => {
    const asked = Date.now();
    stats.pinged = asked;
    setTimeout(() => {
      if (gone || notice || (stats.ponged || 0) >= asked) return;
      notice = document.createElement("div");
      notice.className = "rtt-not-live";
      notice.textContent =
        `Not live any more: the kernel that drew ${label} was restarted or shut down, so nothing runs ` +
        "here now. What you see is its last frame; run the section again for a live view.";
      notice.style.cssText = "position: absolute; left: 0; right: 0; top: 0; padding: 4px 8px; " +
        "background: rgba(255, 236, 179, 0.95); color: #5d4037; font: 13px sans-serif";
      el.style.position = "relative";
      el.appendChild(notice);
      showCaption(false);
    }, LIMITS.ping_ms);
    try {
      model.send({ type: "ping" });
    } catch (error) {
      // a model cut off its kernel may refuse to send: the answer will not come, and the notice shows
    }
  };
  model.on("comm_live_update", onCutOff);

  // Each time the frame (re)loads its page: a new viewer, which asks for the whole scene.
  frame.addEventListener("load", () => {
    const win = frame.contentWindow;
    if (!win || typeof win.viewer === "undefined") return;  // the empty page before srcdoc
    viewer = win.viewer;
    stats.page = win.rttPage;
    owed = 0;  // what the old page drew: its wait died with it, and the hello's scene starts the window afresh
    answered += 1;
    model.send({ type: "hello", id });
  });
  // While this view is on a page someone can see, it says so now and then: a run that no page shows
  // pauses, and goes on when one does (tutorial/notebook/runs.py); a still scene sends no frame to answer.
  const here = setInterval(() => {
    if (gone || document.visibilityState !== "visible") return;
    try {
      model.send({ type: "here" });
    } catch (error) {
      // a model cut off its kernel may refuse to send: its caption already says so
    }
  }, LIMITS.here_ms);
  viewerScript(model).then(
    (url) => {
      if (!gone) frame.srcdoc = page(url);
    },
    (error) => {
      console.error(`ros-tank-tutorial view "${label}": ${error.message}`);
      const note = document.createElement("div");
      note.textContent = `This view could not load meshcat's viewer: ${error.message}`;
      el.appendChild(note);
    },
  );
  // The view ends when its output is replaced (it has left the page) or its widget is closed.
  return () => {
    gone = true;
    clearInterval(here);
    model.off("msg:custom", onMessage);
    model.off("change:status", onStatus);
    model.off("comm_live_update", onCutOff);
  };
}

export default { render };

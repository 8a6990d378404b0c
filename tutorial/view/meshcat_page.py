"""The page the project's meshcat server serves at ``/static/``: meshcat's own page, and two changes.

It loads meshcat's own script and makes meshcat's own ``Viewer``, as
meshcat's ``index.html`` does; then

- **it draws ``set_transforms``**, a frame's transforms in one message
  (:mod:`tutorial.view.meshcat_batch`): each inner command goes to meshcat's
  own ``handle_command``, which also marks the scene for the next render, so
  a frame's transforms are drawn together, in the next animation frame;
- **it drops multisampling on a software renderer**.  meshcat asks for a
  multisampled (antialiased) canvas.  Without a GPU, Chromium rasterizes
  WebGL on the CPU (SwiftShader; Mesa's llvmpipe elsewhere), where 4x
  multisampling costs about half the frame rate (measured, drawing every
  frame on an idle 2-core machine: 8 tanks 31 -> 48 frames/s, the 48-joint
  arm 8 -> 18); on a GPU it is nearly free and is kept.  The page asks
  WebGL which renderer it got and, on a software one, gives meshcat's
  viewer a renderer without it.  ``?antialias=1`` or ``?antialias=0`` in the
  page's URL decides instead.  ``window.rttPage`` says what was chosen:
  ``{renderer: "...", software: true, antialias: false}``.

The page runs in the browser; this module only holds its text (served by
:mod:`tutorial.view.meshcat_server`).
"""

PAGE_HTML = """<!DOCTYPE html>
<html>
  <head>
    <meta charset="utf-8">
    <title>MeshCat</title>
    <style>
      body { margin: 0; }
      #meshcat-pane { width: 100vw; height: 100vh; overflow: hidden; }
    </style>
  </head>
  <body>
    <div id="meshcat-pane"></div>
    <script type="text/javascript" src="main.min.js"></script>
    <script>
      var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
      (function () {
        const handleOne = viewer.handle_command.bind(viewer);
        viewer.handle_command = function (cmd) {
          if (cmd.type === "set_transforms") {
            cmd.commands.forEach(handleOne);
          } else {
            handleOne(cmd);
          }
        };
      })();
      (function () {
        const THREE = MeshCat.THREE;
        const old = viewer.renderer;
        const gl = old.getContext();
        const info = gl.getExtension("WEBGL_debug_renderer_info");
        const name = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
        const software = /swiftshader|llvmpipe|softpipe|software/i.test(name);
        const asked = new URLSearchParams(location.search).get("antialias");
        const antialias = asked === null ? !software : asked !== "0";
        if (!antialias) {
          const renderer = new THREE.WebGLRenderer({antialias: false, alpha: true});
          renderer.shadowMap.enabled = old.shadowMap.enabled;
          renderer.shadowMap.type = old.shadowMap.type;
          renderer.setPixelRatio(old.getPixelRatio());
          const size = old.getSize(new THREE.Vector2());
          renderer.setSize(size.x, size.y);
          old.domElement.replaceWith(renderer.domElement);
          old.dispose();
          viewer.renderer = renderer;
          viewer.set_dirty();
        }
        window.rttPage = {renderer: name, software: software, antialias: antialias};
      })();
      try {
        viewer.connect();
      } catch (e) {
        console.info("Not connected to MeshCat websocket server: ", e);
      }
    </script>
  </body>
</html>
"""

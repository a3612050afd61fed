"""Instrumentation of the viewer page for the browser tests and ``benches/view.py``."""

#: Chromium flags for headless runs without a GPU: software WebGL (SwiftShader) and software
#: compositing (3 x the frame rate of Chromium's default GPU compositing on SwiftShader).
HEADLESS_CHROMIUM_ARGS = ["--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--disable-gpu-compositing"]

#: An init script counting the animation frames in which the page drew with WebGL, in
#: ``window.__frames`` (the viewer renders on demand: only frames that changed are drawn).
FRAME_COUNTER_JS = """
(() => {
  window.__frames = 0; let drawn = false;
  const raf = window.requestAnimationFrame.bind(window);
  window.requestAnimationFrame = (cb) => raf((ts) => { drawn = false; cb(ts); if (drawn) window.__frames++; });
  for (const C of [WebGLRenderingContext, WebGL2RenderingContext]) {
    for (const name of ["drawElements", "drawArrays", "drawElementsInstanced", "drawArraysInstanced"]) {
      const f = C.prototype[name];
      if (f) C.prototype[name] = function (...a) { drawn = true; return f.apply(this, a); };
    }
  }
})();
"""

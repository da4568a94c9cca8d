// In-page WebGL 2 helpers shared by the GPU decoder pages (bc6h_gpu.mjs, compact_gpu.mjs): the
// page loads it with <script src="/webgl_page.js">, the page's server serves this file.
// Each throws with the GL's own log on failure, so the test prints what went wrong.
window.webglPage = {
  // A linked program from a vertex and a fragment shader source, made current.
  program(gl, vsSource, fsSource) {
    const compile = (type, src) => {
      const s = gl.createShader(type);
      gl.shaderSource(s, src);
      gl.compileShader(s);
      if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
      return s;
    };
    const prog = gl.createProgram();
    gl.attachShader(prog, compile(gl.VERTEX_SHADER, vsSource));
    gl.attachShader(prog, compile(gl.FRAGMENT_SHADER, fsSource));
    gl.linkProgram(prog);
    if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(prog));
    gl.useProgram(prog);
    return prog;
  },
  // The vertex shader of fullScreenTriangle: attribute `p` in clip space.
  fullScreenVertexShader: '#version 300 es\nin vec2 p; void main() { gl_Position = vec4(p, 0.0, 1.0); }',
  // One triangle covering the viewport, bound to `prog`'s attribute `p`.
  fullScreenTriangle(gl, prog) {
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer());
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array([-1, -1, 3, -1, -1, 3]), gl.STATIC_DRAW);
    const loc = gl.getAttribLocation(prog, 'p');
    gl.enableVertexAttribArray(loc);
    gl.vertexAttribPointer(loc, 2, gl.FLOAT, false, 0, 0);
  },
  // An RGBA32F w × h render target, bound as the framebuffer, with the viewport set to it.
  floatTarget(gl, w, h) {
    const target = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, target);
    gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA32F, w, h);
    gl.bindFramebuffer(gl.FRAMEBUFFER, gl.createFramebuffer());
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, target, 0);
    if (gl.checkFramebufferStatus(gl.FRAMEBUFFER) !== gl.FRAMEBUFFER_COMPLETE)
      throw new Error('incomplete RGBA32F target');
    gl.viewport(0, 0, w, h);
  },
  // The bytes of a typed array as base64 (how a page function returns binary data).
  base64(array) {
    const u8 = new Uint8Array(array.buffer, array.byteOffset, array.byteLength);
    let s = '';
    for (let i = 0; i < u8.length; i += 0x8000) s += String.fromCharCode.apply(null, u8.subarray(i, i + 0x8000));
    return btoa(s);
  },
};

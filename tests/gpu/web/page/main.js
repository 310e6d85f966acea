// The page (issue 22): renders one scene description (made by ../render-vtkjs.mjs from a volref scene
// file) with vtk.js 37.4.3's WebGL2 volume mapper into a float (RGBA16F) drawing buffer and returns the
// pixels as read back: premultiplied RGBA, float, rows top to bottom. Nothing here changes how vtk.js
// renders except the jitter seed, pinned through vtk.js's ShaderReplacements API to the scene's
// render.profile_options.jitter (vtk.js: jitter = 0.01 + 0.99 seed).
import '@kitware/vtk.js/Rendering/Profiles/Volume';
import vtkGenericRenderWindow from '@kitware/vtk.js/Rendering/Misc/GenericRenderWindow';
import vtkVolume from '@kitware/vtk.js/Rendering/Core/Volume';
import vtkVolumeMapper from '@kitware/vtk.js/Rendering/Core/VolumeMapper';
import vtkImageData from '@kitware/vtk.js/Common/DataModel/ImageData';
import vtkDataArray from '@kitware/vtk.js/Common/Core/DataArray';
import vtkColorTransferFunction from '@kitware/vtk.js/Rendering/Core/ColorTransferFunction';
import vtkPiecewiseFunction from '@kitware/vtk.js/Common/DataModel/PiecewiseFunction';
import vtkLight from '@kitware/vtk.js/Rendering/Core/Light';

// WebGL's default context is multisampled (antialias: true): pixels on the ray box's silhouette then hold
// the shaded colour times the covered fraction of 4 samples, which volref does not mirror (one ray per
// pixel centre). vtk.js asks for the default; the page asks for a single-sampled context instead.
const getContext = HTMLCanvasElement.prototype.getContext;
HTMLCanvasElement.prototype.getContext = function getContextWithoutMsaa(type, options) {
  return getContext.call(this, type, type === 'webgl2' ? { ...options, antialias: false } : options);
};

function decodeFloat32(base64) {
  const bin = atob(base64);
  const bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; ++i) bytes[i] = bin.charCodeAt(i);
  return new Float32Array(bytes.buffer);
}

function encodeFloat32(array) {
  const bytes = new Uint8Array(array.buffer, array.byteOffset, array.byteLength);
  let s = '';
  for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode.apply(null, bytes.subarray(i, i + 0x8000));
  return btoa(s);
}

// d: { width, height, dims, spacing, origin, data (base64 float32), color [[v, r, g, b]...],
//      opacity [[v, a]...], unitDistance, step (world), projection, jitter, shading|null,
//      lights [{type, direction, color}], camera {type, eye, target, up, fovY, height} }
window.renderScene = async function renderScene(d) {
  const container = document.createElement('div');
  container.style.width = `${d.width}px`;
  container.style.height = `${d.height}px`;
  document.body.appendChild(container);
  const grw = vtkGenericRenderWindow.newInstance({ background: [0, 0, 0, 0], listenWindowResize: false });
  grw.setContainer(container);
  const glrw = grw.getApiSpecificRenderWindow();
  glrw.setSize(d.width, d.height);
  const renderer = grw.getRenderer();
  const renderWindow = grw.getRenderWindow();
  renderer.setBackground(0, 0, 0, 0);

  const image = vtkImageData.newInstance();
  image.setDimensions(d.dims);
  image.setSpacing(d.spacing);
  image.setOrigin(d.origin);
  image.getPointData().setScalars(vtkDataArray.newInstance({ numberOfComponents: 1, values: decodeFloat32(d.data) }));

  const mapper = vtkVolumeMapper.newInstance();
  mapper.setInputData(image);
  mapper.setSampleDistance(d.step);
  mapper.setMaximumSamplesPerRay(100000);
  if (d.projection === 'mip') mapper.setBlendModeToMaximumIntensity();
  else if (d.projection === 'minip') mapper.setBlendModeToMinimumIntensity();
  else mapper.setBlendModeToComposite();
  const seed = (d.jitter - 0.01) / 0.99;
  mapper.getViewSpecificProperties().OpenGL = {
    ShaderReplacements: [{
      shaderType: 'Fragment',
      originalValue: 'fragmentSeed = getFragmentSeed();',
      replacementValue: `fragmentSeed = ${seed.toFixed(9)};`,
      replaceFirst: false,
      replaceAll: false,
    }],
  };

  const ctf = vtkColorTransferFunction.newInstance();
  for (const [v, r, g, b] of d.color) ctf.addRGBPoint(v, r, g, b);
  const otf = vtkPiecewiseFunction.newInstance();
  for (const [v, a] of d.opacity) otf.addPoint(v, a);
  const actor = vtkVolume.newInstance();
  actor.setMapper(mapper);
  const prop = actor.getProperty();
  prop.setRGBTransferFunction(0, ctf);
  prop.setScalarOpacity(0, otf);
  prop.setScalarOpacityUnitDistance(0, d.unitDistance);
  prop.setInterpolationTypeToLinear();
  prop.setUseGradientOpacity(0, false);
  if (d.shading) {
    prop.setShade(true);
    prop.setAmbient(d.shading.ka);
    prop.setDiffuse(d.shading.kd);
    prop.setSpecular(d.shading.ks);
    prop.setSpecularPower(d.shading.n);
  } else {
    prop.setShade(false);
  }
  renderer.addVolume(actor);

  renderer.setAutomaticLightCreation(false);
  renderer.removeAllLights();
  renderer.setTwoSidedLighting(Boolean(d.shading && d.shading.twoSided));
  for (const l of d.lights) {
    const light = vtkLight.newInstance();
    light.setColor(...l.color);
    light.setIntensity(1);
    if (l.type === 'headlight') {
      light.setLightTypeToHeadLight();
    } else {
      light.setLightTypeToSceneLight();
      light.setPositional(false);
      light.setPosition(...l.direction);  // direction of travel: focal point - position = -direction
      light.setFocalPoint(0, 0, 0);
    }
    renderer.addLight(light);
  }

  const camera = renderer.getActiveCamera();
  camera.setPosition(...d.camera.eye);
  camera.setFocalPoint(...d.camera.target);
  camera.setViewUp(...d.camera.up);
  if (d.camera.type === 'orthographic') {
    camera.setParallelProjection(true);
    camera.setParallelScale(d.camera.height / 2);
  } else {
    camera.setParallelProjection(false);
    camera.setViewAngle(d.camera.fovY);
  }
  renderer.resetCameraClippingRange();

  renderWindow.render();
  const gl = glrw.getContext();
  if (typeof gl.drawingBufferStorage !== 'function') throw new Error('this browser has no WebGL2 drawingBufferStorage');
  gl.drawingBufferStorage(gl.RGBA16F, d.width, d.height);
  renderWindow.render();
  const pixels = new Float32Array(d.width * d.height * 4);
  gl.readPixels(0, 0, d.width, d.height, gl.RGBA, gl.FLOAT, pixels);
  const err = gl.getError();
  if (err !== gl.NO_ERROR) throw new Error(`readPixels: WebGL error ${err}`);
  // rows bottom to top (OpenGL) -> top to bottom (volref's images)
  const out = new Float32Array(pixels.length);
  const row = d.width * 4;
  for (let y = 0; y < d.height; ++y) out.set(pixels.subarray((d.height - 1 - y) * row, (d.height - y) * row), y * row);
  const info = {
    renderer: gl.getParameter(gl.RENDERER),
    version: gl.getParameter(gl.VERSION),
    drawingBufferFormat: gl.drawingBufferFormat,
  };
  grw.delete();
  container.remove();
  return { pixels: encodeFloat32(out), info };
};
window.pageReady = true;

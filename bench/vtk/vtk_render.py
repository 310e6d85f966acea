#!/usr/bin/python3
"""Renders one of the comparison's volref scenes (bench/vtk/scenes/*.json) with one of VTK's
volume mappers and times it.

    xvfb-run -a -s "-screen 0 1024x768x24" /usr/bin/python3 bench/vtk/vtk_render.py \
        bench/vtk/scenes/composite.json --mapper fixed --threads 2 --frames 3 -o /tmp/f.png

Debian's python3-vtk9 (VTK 9.1) under Debian's /usr/bin/python3; VTK's OpenGL render window
needs an X server (Xvfb). --mapper fixed: vtkFixedPointVolumeRayCastMapper (CPU, threaded by
vtkMultiThreader); --mapper gpu: vtkGPUVolumeRayCastMapper, which here runs on Mesa's llvmpipe
(software OpenGL on the CPU; its thread count is LP_NUM_THREADS, which must be in the environment
before the process starts: the driver sets it).

The scene is read from the volref JSON so that both renderers get the same numbers. Only what
these scenes use is supported (a Marschner-Lobb field, a data-domain transfer function, optional
shading with one headlight, a perspective camera, composite or mip); anything else is an error.

Timing: the volume is built (numpy, float32) and the pipeline set up first (not timed); then
--warmup frames (not timed: VTK's per-volume work happens there, i.e. the fixed-point mapper's
15-bit scalar conversion, gradient encoding and min/max blocks, the GPU mapper's shader
compilation and 3-D texture upload), then --frames timed frames, each rw.Render() followed by
rw.WaitForCompletion() (glFinish). The image of the last frame is written as an 8-bit RGB PNG.
Prints one JSON object on stdout.

Lighting of shaded scenes: by default (--light white) an explicit headlight with ambient, diffuse
and specular colour (1, 1, 1) and intensity 1, which is the scene's light (volref: I ka m + ...).
The light VTK creates when there is none has ambient colour (0, 0, 0), and the fixed-point mapper
multiplies ka by it, dropping the ambient term (vtkEncodedGradientShader); --light default uses that
light. The renderer's TwoSidedLighting stays on (VTK's default): the scenes ask for two-sided
shading to match.
"""
import argparse
import json
import math
import os
import sys
import time

import numpy as np

import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (registers the OpenGL render window)
import vtkmodules.vtkRenderingVolumeOpenGL2  # noqa: F401  (the GPU mapper and the ray-cast display helper)
from vtkmodules.util import numpy_support
from vtkmodules.vtkCommonCore import vtkMultiThreader, vtkVersion
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkPiecewiseFunction
from vtkmodules.vtkIOImage import vtkPNGWriter
from vtkmodules.vtkRenderingCore import (vtkColorTransferFunction, vtkLight, vtkRenderer, vtkRenderWindow,
                                         vtkVolume, vtkVolumeProperty, vtkWindowToImageFilter)
from vtkmodules.vtkRenderingVolume import vtkFixedPointVolumeRayCastMapper, vtkGPUVolumeRayCastMapper


def fail(message):
    sys.exit("vtk_render.py: " + message)


def marschner_lobb(dims, fm, alpha):
    """The Marschner-Lobb signal as volref's procedural field defines it (core/grid/ProceduralField.cpp):
    voxel i of n sits at u = -1 + 2 i / (n - 1); evaluated in double, stored as float32, x fastest."""
    def coord(n):
        return np.zeros(1) if n == 1 else -1.0 + 2.0 * np.arange(n, dtype=np.float64) / (n - 1)
    x, y, z = coord(dims[0]), coord(dims[1]), coord(dims[2])
    r = np.sqrt(x[None, :] ** 2 + y[:, None] ** 2)                      # (ny, nx)
    rho = np.cos(2.0 * math.pi * fm * np.cos(math.pi * r / 2.0))
    v = (1.0 - np.sin(math.pi * z / 2.0))[:, None, None] + alpha * (1.0 + rho)[None, :, :]
    v /= 2.0 * (1.0 + alpha)
    return v.astype(np.float32)                                          # shape (nz, ny, nx)


def build_volume(scene):
    vs = scene["volume"]
    src = vs["source"]
    if not isinstance(src, dict) or src.get("field") != "marschner-lobb":
        fail("only the marschner-lobb field is supported")
    dims = src.get("dims", [2, 2, 2])
    values = marschner_lobb(dims, src.get("fm", 6.0), src.get("alpha", 0.25))
    image = vtkImageData()
    image.SetDimensions(*dims)
    image.SetOrigin(*vs.get("origin", [0, 0, 0]))
    image.SetSpacing(*vs.get("spacing", [1, 1, 1]))
    array = numpy_support.numpy_to_vtk(values.ravel(), deep=True)
    array.SetName("ML")
    image.GetPointData().SetScalars(array)
    return image, float(values.min()), float(values.max())


def build_property(scene):
    vs = scene["volume"]
    tf = vs.get("transfer", {})
    if tf.get("domain", "data") != "data" or "gradient_opacity" in tf:
        fail("only data-domain transfer functions without gradient opacity are supported")
    if vs.get("interpolation", "trilinear") != "trilinear":
        fail("only trilinear interpolation is supported")
    color = vtkColorTransferFunction()
    color.SetColorSpaceToRGB()
    for v, r, g, b in tf["color"]:
        color.AddRGBPoint(v, r, g, b)
    opacity = vtkPiecewiseFunction()
    for v, a in tf["opacity"]:
        opacity.AddPoint(v, a)
    prop = vtkVolumeProperty()
    prop.SetColor(color)
    prop.SetScalarOpacity(opacity)
    prop.SetScalarOpacityUnitDistance(tf.get("opacity_unit_distance", 1.0))
    prop.SetInterpolationTypeToLinear()
    shading = vs.get("shading")
    if shading is not None:
        if shading.get("model", "blinn-phong") != "blinn-phong" or shading.get("kl", 0) != 0 or shading.get("kc", 1) != 1:
            fail("only blinn-phong shading without depth cueing is supported")
        lights = scene.get("lights", [{"type": "headlight"}])
        if len(lights) != 1 or lights[0].get("type", "headlight") != "headlight" or lights[0].get("color", [1, 1, 1]) != [1, 1, 1]:
            fail("only one white headlight is supported (VTK's default light)")
        prop.ShadeOn()
        prop.SetAmbient(shading.get("ka", 0.1))
        prop.SetDiffuse(shading.get("kd", 0.7))
        prop.SetSpecular(shading.get("ks", 0.2))
        prop.SetSpecularPower(shading.get("n", 10))
    return prop, shading, (color, opacity)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--mapper", choices=["fixed", "gpu"], required=True)
    ap.add_argument("--threads", type=int, default=0, help="0: VTK's default")
    ap.add_argument("--frames", type=int, default=3)
    ap.add_argument("--warmup", type=int, default=1)
    ap.add_argument("-o", "--output", help="PNG of the last frame")
    ap.add_argument("--light", choices=["white", "default"], default="white",
                    help="white (the default): one headlight of colour (1, 1, 1) for ambient, diffuse "
                         "and specular, the scene's light; default: the light VTK creates itself, whose "
                         "ambient colour is (0, 0, 0), so the fixed-point mapper drops the ambient term")
    args = ap.parse_args()

    with open(args.scene) as f:
        scene = json.load(f)
    t_start = time.perf_counter()
    if args.threads > 0:
        # Before any mapper exists: new vtkMultiThreaders take min(default, maximum) threads.
        vtkMultiThreader.SetGlobalMaximumNumberOfThreads(args.threads)
        vtkMultiThreader.SetGlobalDefaultNumberOfThreads(args.threads)

    image, vmin, vmax = build_volume(scene)
    prop, shading, keep = build_property(scene)
    render = scene.get("render", {})
    if render.get("step_units", "voxel") != "voxel":
        fail("only step_units voxel is supported")
    spacing = min(scene["volume"].get("spacing", [1, 1, 1]))
    step = render.get("step", 0.5) * spacing

    if args.mapper == "fixed":
        mapper = vtkFixedPointVolumeRayCastMapper()
        if args.threads > 0:
            mapper.SetNumberOfThreads(args.threads)
        mapper.SetImageSampleDistance(1.0)      # one ray per pixel
        mapper.SetInteractiveSampleDistance(step)
    else:
        mapper = vtkGPUVolumeRayCastMapper()
        mapper.SetUseJittering(0)
    mapper.SetInputData(image)
    mapper.AutoAdjustSampleDistancesOff()       # otherwise SampleDistance is ignored
    mapper.LockSampleDistanceToInputSpacingOff()
    mapper.SetSampleDistance(step)
    projection = render.get("projection", "composite")
    if projection == "composite":
        mapper.SetBlendModeToComposite()
    elif projection == "mip":
        mapper.SetBlendModeToMaximumIntensity()
    else:
        fail("only composite and mip are supported")

    volume = vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)

    img = scene.get("image", {})
    width, height = img.get("width", 256), img.get("height", 256)
    bg = img.get("background", [0, 0, 0, 0])
    ren = vtkRenderer()
    ren.SetBackground(bg[0] * bg[3], bg[1] * bg[3], bg[2] * bg[3])
    ren.AddVolume(volume)
    if shading is not None and args.light == "white":
        light = vtkLight()
        light.SetLightTypeToHeadlight()
        light.SetIntensity(1.0)
        light.SetAmbientColor(1.0, 1.0, 1.0)
        light.SetDiffuseColor(1.0, 1.0, 1.0)
        light.SetSpecularColor(1.0, 1.0, 1.0)
        ren.AddLight(light)
    rw = vtkRenderWindow()
    rw.SetOffScreenRendering(1)
    rw.SetMultiSamples(0)
    rw.SetSize(width, height)
    rw.AddRenderer(ren)

    cam_spec = scene["camera"]
    if cam_spec.get("type") != "perspective":
        fail("only perspective cameras are supported")
    cam = ren.GetActiveCamera()
    cam.SetPosition(*cam_spec.get("eye", [0, 0, 1]))
    cam.SetFocalPoint(*cam_spec.get("target", [0, 0, 0]))
    cam.SetViewUp(*cam_spec.get("up", [0, 1, 0]))
    cam.OrthogonalizeViewUp()
    cam.SetViewAngle(cam_spec.get("fov_y", 30))   # vertical angle (UseHorizontalViewAngle off)
    ren.ResetCameraClippingRange()
    setup = time.perf_counter() - t_start

    warm = []
    for _ in range(args.warmup):
        t0 = time.perf_counter()
        rw.Render()
        rw.WaitForCompletion()
        warm.append(time.perf_counter() - t0)
    frames = []
    for _ in range(args.frames):
        t0 = time.perf_counter()
        rw.Render()
        rw.WaitForCompletion()
        frames.append(time.perf_counter() - t0)

    if args.output:
        w2i = vtkWindowToImageFilter()
        w2i.SetInput(rw)
        w2i.SetInputBufferTypeToRGB()
        w2i.ReadFrontBufferOff()
        w2i.Update()
        writer = vtkPNGWriter()
        writer.SetFileName(args.output)
        writer.SetInputConnection(w2i.GetOutputPort())
        writer.Write()

    caps = rw.ReportCapabilities() or ""
    def capability(name):
        return next((line.split(":", 1)[1].strip() for line in caps.splitlines() if line.startswith(name)), "")
    threads = mapper.GetNumberOfThreads() if args.mapper == "fixed" else int(os.environ.get("LP_NUM_THREADS", "0"))
    print(json.dumps({
        "mapper": args.mapper, "threads": threads, "setup_s": setup, "warmup_s": warm,
        "frames_s": frames, "data_range": [vmin, vmax], "sample_distance": mapper.GetSampleDistance(),
        "gl_renderer": capability("OpenGL renderer string"), "gl_version": capability("OpenGL version string"),
        "vtk_version": vtkVersion.GetVTKVersion(), "light": args.light if shading is not None else "unused",
    }))


if __name__ == "__main__":
    main()

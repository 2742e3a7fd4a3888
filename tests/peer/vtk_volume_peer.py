#!/usr/bin/python3
"""Peer check of the operation "volume": the same scalar volume, transfer function and camera
rendered by VTK's vtkFixedPointVolumeRayCastMapper (Kitware's CPU ray caster; emission-absorption,
colour and opacity interpolated linearly, opacity per "scalar opacity unit distance") and by
`mfr render` (the oracle, and a GPU method), compared with `mfr compare`.

usage: vtk_volume_peer.py MFR_BINARY WORK_DIR
Exit 0 when both renderers agree (RMSE, mean FLIP below the bounds below) and a deliberately
wrong unit distance (x3) on our side is clearly worse; 1 otherwise (with the numbers printed).
Needs an X display (ctest runs it through tests/app/run-with-display)."""
import json
import math
import os
import subprocess
import sys

import vtk

N = 48
SIZE = (240, 200)
EYE, TARGET, UP = (2.0, 1.5, 3.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0)
ORTHO_HEIGHT = 3.6
NEAR, FAR = 0.5, 10.0
UNIT = 0.2
STEP = 0.01
# (value, r, g, b, opacity)
POINTS = [(0.0, 0.0, 0.0, 0.0, 0.0), (0.5, 0.2, 0.5, 1.0, 0.3), (1.0, 1.0, 0.6, 0.1, 0.8)]
# RMSE / mean FLIP bounds (measured: 0.0033 / 0.0172 for the oracle and abuffer-ll), and how much
# worse the wrong unit distance must be (measured: RMSE 0.1201).
MAX_RMSE, MAX_FLIP, WORSE = 0.01, 0.03, 3.0


def field(x, y, z):
    r2 = x * x + y * y + z * z
    blob = math.exp(-((x - 0.3) ** 2 + y * y + (z + 0.2) ** 2) / (2 * 0.15 ** 2))
    return min(1.0, 0.8 * math.exp(-r2 / (2 * 0.35 ** 2)) + 0.25 * (x + 1.0) / 2.0 + 0.7 * blob)


def write_volume(path):
    image = vtk.vtkImageData()
    image.SetDimensions(N, N, N)
    h = 2.0 / (N - 1)
    image.SetSpacing(h, h, h)
    image.SetOrigin(-1.0, -1.0, -1.0)
    values = vtk.vtkFloatArray()
    values.SetName("f")
    values.SetNumberOfTuples(N * N * N)
    i = 0
    for k in range(N):
        for j in range(N):
            for ii in range(N):
                values.SetValue(i, field(-1 + ii * h, -1 + j * h, -1 + k * h))
                i += 1
    image.GetPointData().SetScalars(values)
    writer = vtk.vtkXMLImageDataWriter()
    writer.SetFileName(path)
    writer.SetInputData(image)
    writer.Write()
    return image


def render_vtk(image, path):
    color = vtk.vtkColorTransferFunction()
    opacity = vtk.vtkPiecewiseFunction()
    for v, r, g, b, a in POINTS:
        color.AddRGBPoint(v, r, g, b)
        opacity.AddPoint(v, a)
    prop = vtk.vtkVolumeProperty()
    prop.SetColor(color)
    prop.SetScalarOpacity(opacity)
    prop.SetScalarOpacityUnitDistance(UNIT)
    prop.SetInterpolationTypeToLinear()
    prop.ShadeOff()
    mapper = vtk.vtkFixedPointVolumeRayCastMapper()
    mapper.SetInputData(image)
    mapper.AutoAdjustSampleDistancesOff()
    mapper.SetSampleDistance(STEP)
    mapper.SetImageSampleDistance(1.0)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    renderer = vtk.vtkRenderer()
    renderer.SetBackground(1.0, 1.0, 1.0)
    renderer.AddVolume(volume)
    camera = renderer.GetActiveCamera()
    camera.ParallelProjectionOn()
    camera.SetParallelScale(ORTHO_HEIGHT / 2.0)
    camera.SetPosition(*EYE)
    camera.SetFocalPoint(*TARGET)
    camera.SetViewUp(*UP)
    camera.SetClippingRange(NEAR, FAR)
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetMultiSamples(0)
    window.SetSize(*SIZE)
    window.AddRenderer(renderer)
    window.Render()
    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.SetInputBufferTypeToRGB()
    grab.ReadFrontBufferOff()
    grab.Update()
    writer = vtk.vtkPNGWriter()
    writer.SetFileName(path)
    writer.SetInputConnection(grab.GetOutputPort())
    writer.Write()


def write_scene(path, unit):
    scene = {
        "background": [1, 1, 1],
        "volumes": [{"file": "field.vti",
                     "transfer": {"points": [list(p) for p in POINTS], "unit_distance": unit}}],
        "views": [{"name": "peer", "eye": list(EYE), "target": list(TARGET), "up": list(UP),
                   "projection": "orthographic", "height": ORTHO_HEIGHT, "near": NEAR, "far": FAR}],
    }
    with open(path, "w") as f:
        json.dump(scene, f)


def mfr(binary, *args):
    out = subprocess.run([binary, *args], capture_output=True, text=True)
    if out.returncode != 0:
        print("mfr", " ".join(args), "failed:", out.stdout, out.stderr)
        sys.exit(1)
    return out.stdout


def metrics(binary, reference, test):
    text = mfr(binary, "compare", reference, test, "--metric", "rmse,flip")
    rmse = float(text.split("rmse ")[1].split()[0])
    flip = float(text.split("flip mean ")[1].split()[0])
    return rmse, flip


def main():
    binary, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    image = write_volume(os.path.join(work, "field.vti"))
    peer = os.path.join(work, "vtk.png")
    render_vtk(image, peer)
    size = "%dx%d" % SIZE
    ok = True
    results = {}
    for label, unit, method in (("oracle", UNIT, "oracle"), ("abuffer-ll", UNIT, "abuffer-ll"),
                                ("oracle, unit x3", 3 * UNIT, "oracle")):
        scene = os.path.join(work, "scene-%s.mfrscene" % label.replace(" ", "").replace(",", ""))
        write_scene(scene, unit)
        ours = scene.replace(".mfrscene", ".png")
        mfr(binary, "render", scene, "--view", "peer", "--size", size, "--step", str(STEP), "-m", method,
            "--op", "volume", "-o", ours)
        results[label] = metrics(binary, peer, ours)
        print("VTK vs mfr %-16s rmse %.4f  flip mean %.4f" % (label, *results[label]))
    for label in ("oracle", "abuffer-ll"):
        rmse, flip = results[label]
        if rmse > MAX_RMSE or flip > MAX_FLIP:
            print("FAIL: %s differs from VTK beyond rmse %.3f / flip %.3f" % (label, MAX_RMSE, MAX_FLIP))
            ok = False
    if results["oracle, unit x3"][0] < WORSE * results["oracle"][0]:
        print("FAIL: a wrong unit distance is not clearly worse: the comparison cannot tell")
        ok = False
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())

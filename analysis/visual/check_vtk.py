"""Reads a rubblepile run's VTK output with the library ParaView is built on (VTK 9, through pyvista),
checks it against the run's CSV snapshots, and renders one snapshot to a PNG with VTK's own tensor glyphs.

    python analysis/visual/check_vtk.py RUN_DIR OUT.png [SNAPSHOT_INDEX]

Needs `pip install pyvista` (offscreen rendering; no display needed). Exits non-zero when a check fails.
"""
import csv
import sys
import xml.etree.ElementTree as ET

import numpy as np
import pyvista as pv
import vtk

run_dir, out_png = sys.argv[1], sys.argv[2]
k = int(sys.argv[3]) if len(sys.argv) > 3 else None
pv.OFF_SCREEN = True

# 1. The collection: VTK's own .pvd reader sees every snapshot time.
reader = pv.get_reader(f"{run_dir}/vtk/run.pvd")
pvd_times = [float(d.get("timestep")) for d in ET.parse(f"{run_dir}/vtk/run.pvd").iter("DataSet") if d.get("part") == "0"]
assert np.allclose(reader.time_values, pvd_times, rtol=0, atol=0), (reader.time_values, pvd_times)
if k is None:
    k = len(pvd_times) - 1
print(f"{len(pvd_times)} snapshots, t = {pvd_times[0]} .. {pvd_times[-1]} s; checking snapshot {k} (t = {pvd_times[k]} s)")

# 2. One piece, read by VTK, against the CSV snapshot written by the same run.
piece = f"{run_dir}/vtk/particles_{k}.vtp"
m = pv.read(piece)
with open(f"{run_dir}/snapshots/{k}.csv") as f:
    rows = list(csv.DictReader(f))
assert m.n_points == len(rows)
pos = np.array([[float(r[c]) for c in "xyz"] for r in rows])
axes = np.array([[float(r[c]) for c in "abc"] for r in rows])
assert np.array_equal(np.asarray(m.points), pos), "VTK points = CSV positions, bit for bit"
shape = np.asarray(m.point_data["shape"]).reshape(-1, 3, 3)  # VTK tensor components: column j = shape[:, j, :]
for i, r in enumerate(rows):
    q = np.array([float(r[c]) for c in ("qa", "qb", "qc", "qd")])
    q /= np.linalg.norm(q)
    a, b, c, d = q  # vector part first, scalar last
    # Rotation body -> world of the unit quaternion d + a i + b j + c k (Roig03 Eq. 21's R(q) is its transpose).
    rot = np.array([
        [d*d + a*a - b*b - c*c, 2*(a*b - c*d), 2*(a*c + b*d)],
        [2*(a*b + c*d), d*d - a*a + b*b - c*c, 2*(b*c - a*d)],
        [2*(a*c - b*d), 2*(b*c + a*d), d*d - a*a - b*b + c*c],
    ])
    for j in range(3):
        col = shape[i, j, :]
        assert abs(np.linalg.norm(col) - axes[i, j]) < 1e-9 * axes[i, j], (i, j)
        assert np.linalg.norm(col / axes[i, j] - rot[:, j]) < 1e-9, (i, j)
print("points, axes and attitudes agree with the CSV snapshot ")

# 3. Render with VTK's tensor glyphs: a unit sphere mapped by each body's shape tensor is the body itself.
m.GetPointData().SetActiveTensors("shape")
m.set_active_scalars("speed")
sphere = vtk.vtkSphereSource()
sphere.SetRadius(1.0)
sphere.SetThetaResolution(32)
sphere.SetPhiResolution(16)
glyphs = vtk.vtkTensorGlyph()
glyphs.SetInputData(m)
glyphs.SetSourceConnection(sphere.GetOutputPort())
glyphs.ExtractEigenvaluesOff()
glyphs.ThreeGlyphsOff()
glyphs.SymmetricOff()
glyphs.ClampScalingOff()
glyphs.SetScaleFactor(1.0)
glyphs.ColorGlyphsOn()
glyphs.SetColorModeToScalars()
glyphs.Update()
bodies = pv.wrap(glyphs.GetOutput())
p = pv.Plotter(off_screen=True, window_size=(800, 800))
p.set_background("black")
p.add_mesh(bodies, scalars="speed", cmap="viridis", smooth_shading=True,
           scalar_bar_args={"title": "speed (m/s)", "color": "white"})
p.add_text(f"ParaView's VTK, tensor glyphs: t = {pvd_times[k]:.0f} s", color="white", font_size=12)
p.camera_position = "iso"
p.screenshot(out_png)
print(f"wrote {out_png}")

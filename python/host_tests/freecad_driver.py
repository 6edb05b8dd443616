"""Run by test_freecad.py inside `freecadcmd` (FreeCAD's own Python, the wheel in its Mod
folder): for each job of the JSON file $VSR_FREECAD_JOBS, a new document with a Mesh object
read from the model by FreeCAD, the macro's entry point on it, the document saved and reopened.
Writes the Mesh objects' points and facets to JOB["out"] (.npz) and "ok" to $VSR_FREECAD_DONE.

freecadcmd exits 0 when a script raises, hence the explicit exit status.
"""

import importlib.util
import json
import os
import sys
import traceback


def arrays(mesh):
    import numpy as np

    points, facets = mesh.Topology
    return np.array([(p.x, p.y, p.z) for p in points]), np.array(facets, dtype=np.int64)


def run_job(macro, job):
    import FreeCAD
    import Mesh
    import numpy as np

    doc = FreeCAD.newDocument(job["document"])
    source = doc.addObject("Mesh::Feature", "Vault")
    source.Mesh = Mesh.Mesh(job["model"])
    doc.recompute()
    if job["entry"] == "run_in_freecad":  # the macro as Macro > Macros runs it
        FreeCAD.setActiveDocument(doc.Name)
        target = macro.run_in_freecad(**job["settings"])
        summary = ""
    else:
        target, summary = macro.form_find_object(
            doc, source, anchored=job["anchored"], **job["settings"]
        )
    found_points, found_facets = arrays(target.Mesh)
    source_points, source_facets = arrays(source.Mesh)
    name = target.Name
    doc.saveAs(job["fcstd"])
    FreeCAD.closeDocument(doc.Name)

    reopened = FreeCAD.openDocument(job["fcstd"])
    reloaded_points, reloaded_facets = arrays(reopened.getObject(name).Mesh)
    labels = [o.Label for o in reopened.Objects]
    FreeCAD.closeDocument(reopened.Name)
    np.savez(
        job["out"],
        source_points=source_points,
        source_facets=source_facets,
        found_points=found_points,
        found_facets=found_facets,
        reloaded_points=reloaded_points,
        reloaded_facets=reloaded_facets,
        labels=np.array(labels),
        summary=np.array(summary),
        freecad_version=np.array(".".join(FreeCAD.Version()[:3])),
    )


def main():
    spec = importlib.util.spec_from_file_location("freecad_macro", os.environ["VSR_MACRO"])
    macro = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(macro)
    with open(os.environ["VSR_FREECAD_JOBS"]) as f:
        jobs = json.load(f)
    for job in jobs:
        run_job(macro, job)
    with open(os.environ["VSR_FREECAD_DONE"], "w") as f:
        f.write("ok\n")


try:
    main()
except BaseException:  # noqa: BLE001 - any failure must reach the exit status
    traceback.print_exc()
    sys.stderr.flush()
    os._exit(1)
sys.exit(0)

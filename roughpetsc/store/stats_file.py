"""The file of ``-mode stats -stats_h5``: layout, writer and reader.

Layout::

    /                  attrs: settings, surface_options, versions, grid (JSON text, and each entry as
                              "<key>.<name>"), conventions
    /seeds             (n,) the white-noise seed of each realisation in index order (-1: the one
                              surface of the options, not a generated ensemble member)
    /mean, /std, /closed_form   attrs: one per quantity (std: sample std, ddof = 1)
    /per_surface/<q>   (n,) every summary quantity per realisation, index order
    /histograms/edges  (bins + 1,) and /histograms/<q> (bins,) the pooled densities
    /pdf_l1/<q>        attrs: l1, l1_noise, closed_form, samples, alpha
"""

import json

import numpy as np

from . import write as write_file

ROOT_RECORDS = ("settings", "surface_options", "versions", "grid")
SCALAR_GROUPS = ("mean", "std", "closed_form")


def write(path, document):
    """Write the stats result document (:func:`roughpetsc.stats_output.result_document`) as HDF5, atomically."""
    def build(f):
        for key in ROOT_RECORDS:
            f.attrs[key] = json.dumps(document[key])
            for name, value in document[key].items():
                f.attrs[f"{key}.{name}"] = value
        f.attrs["conventions"] = document["conventions"]
        f.create_dataset("seeds", data=np.array([-1 if s is None else s for s in document["seeds"]]))
        for group in SCALAR_GROUPS:
            g = f.create_group(group)
            for name, value in (document[group] or {}).items():
                g.attrs[name] = value
        g = f.create_group("per_surface")
        for name, values in document["per_surface"].items():
            g.create_dataset(name, data=np.asarray(values))
        g = f.create_group("histograms")
        g.create_dataset("edges", data=np.asarray(document["histogram_edges"]))
        for name, values in document["histogram_density"].items():
            g.create_dataset(name, data=np.asarray(values))
        g = f.create_group("pdf_l1")
        for name, entry in document["pdf_l1"].items():
            sub = g.create_group(name)
            for key, value in entry.items():
                sub.attrs[key] = value

    write_file(path, build)


def read(path):
    """A stats file as the parts of the result document it holds (numbers as numpy values)."""
    import h5py

    with h5py.File(path, "r") as f:
        out = {key: json.loads(f.attrs[key]) for key in ROOT_RECORDS}
        out["conventions"] = str(f.attrs["conventions"])
        out["seeds"] = [None if s < 0 else int(s) for s in f["seeds"][()]]
        for group in SCALAR_GROUPS:
            out[group] = dict(f[group].attrs) or None
        out["per_surface"] = {name: f["per_surface"][name][()] for name in f["per_surface"]}
        out["histogram_edges"] = f["histograms/edges"][()]
        out["histogram_density"] = {name: f["histograms"][name][()] for name in f["histograms"] if name != "edges"}
        out["pdf_l1"] = {name: dict(f["pdf_l1"][name].attrs) for name in f["pdf_l1"]}
    return out

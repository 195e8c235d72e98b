"""The macro shapes a scene may name, one object each: how it is meshed and what ``ngcontact check`` lists.

:data:`MACRO_SHAPES` maps ``geometry.shape`` to a :class:`MacroShape`:
the built-in femur with its hip stem (:mod:`ngcontact.geometry.femur`,
:mod:`ngcontact.geometry.femur3d`), the coaxial tubes and the block on a base
(:mod:`ngcontact.geometry.bodies`), and two solids of a CAD file
(:mod:`ngcontact.geometry.cad_model`) or two regions of a mesh file
(:mod:`ngcontact.geometry.mesh_model`), whose faces the scene names by
selectors (:mod:`ngcontact.geometry.face_selectors`).
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Protocol

import ngsolve as ng

from ngcontact.errors import GeometryError, SceneError
from ngcontact.geometry import bodies as gm
from ngcontact.geometry import cad_model as cad
from ngcontact.geometry.face_selectors import label_faces, listing
from ngcontact.geometry.mesh_model import MESH_SUFFIXES, read_mesh
from ngcontact.geometry.model_faces import TwoBodyModel, body_index
from ngcontact.geometry.femur import BOUNDARIES, FemurStemDims, femur_stem
from ngcontact.geometry.femur3d import femur_stem_3d
from ngcontact.scene import mesh_size
from ngcontact.scene.file_geometry import file_length_unit
from ngcontact.scene.macro_shapes import BOUNDARY_DOCS
from ngcontact.scene.sections import resolve


@dataclass(frozen=True)
class Sizes:
    """Mesh sizes [m] and polynomial order of one build."""

    maxh: float
    interface_maxh: float
    order: int


class MacroShape(Protocol):
    """One ``geometry.shape``: its mesh, and the lines ``ngcontact check`` prints about it."""

    def build(self, scene, sizes: Sizes) -> gm.MacroGeometry: ...

    def inventory(self, scene) -> list[str]: ...


class FemurStem:
    def build(self, scene, sizes):
        dims = FemurStemDims(**dict(scene.geometry.dimensions or {}))
        if scene.geometry.setting == "3d":
            femur = femur_stem_3d(dims, maxh=sizes.maxh, interface_maxh=sizes.interface_maxh, order=sizes.order)
            return gm.MacroGeometry(mesh=femur.mesh, rough="stem", counter="bone", dims=dict(vars(dims)),
                                    boundaries=dict(BOUNDARY_DOCS[("femur_stem", "3d")]))
        femur = femur_stem(dims, maxh=sizes.maxh, interface_maxh=sizes.interface_maxh)
        return gm.MacroGeometry(mesh=femur.mesh, rough="stem", counter="bone", dims=dict(vars(dims)),
                                boundaries={"interface": "stem-bone interface S_0 (cone and cylinder)", **BOUNDARIES})

    def inventory(self, scene):
        return []


class Coaxial:
    def build(self, scene, sizes):
        g = scene.geometry
        d = dict(g.dimensions or {})
        if g.setting == "plane_strain":
            return gm.coaxial_plane_strain(d["a"], d["b"], d["c"], maxh=sizes.maxh, order=sizes.order)
        if g.setting == "axisymmetric":
            return gm.coaxial_axisymmetric(d["a"], d["b"], d["c"], d["height"], maxh=sizes.maxh)
        return gm.coaxial_3d(d["a"], d["b"], d["c"], d["height"], maxh=sizes.maxh, order=sizes.order)

    def inventory(self, scene):
        return []


class Block:
    def build(self, scene, sizes):
        d = dict(scene.geometry.dimensions or {})
        return gm.block_on_plane(d["length"], d["h_block"], d["h_base"], maxh=sizes.maxh)

    def inventory(self, scene):
        return []


@dataclass
class FileModel:
    """A CAD file read and its selections made: the model, the two bodies, the face labels."""

    model: TwoBodyModel
    rough: int
    counter: int
    labels: dict[int, str]


class FromFile:
    """Two solids of a CAD file; every face selection is checked when the file is read, before meshing."""

    def selected(self, scene) -> FileModel:
        """Read the file and make the scene's selections; the geometry room's refusals under the scene's keys."""
        try:
            return self._selected(scene)
        except GeometryError as exc:  # the geometry room quotes the key it was given
            shown = scene.geometry.file if exc.name == "geometry.file" else exc.value
            raise SceneError(exc.name, shown, exc.allowed) from None

    def _selected(self, scene) -> FileModel:
        g = scene.geometry
        path = resolve(scene, g.file)
        model = read_mesh(path) if path.lower().endswith(MESH_SUFFIXES) else \
            cad.read_cad(path, dim=3 if g.setting == "3d" else 2)
        rough = body_index(model, "geometry.rough", **vars(g.rough))
        counter = body_index(model, "geometry.counter", **vars(g.counter))
        if rough == counter:
            raise SceneError("geometry.counter", vars(g.counter), f"is body {rough}, the rough body too; the "
                             "bodies are\n" + model.bodies_listing())
        selectors = {name: spec.selector(f"geometry.boundaries.{name}")
                     for name, spec in (g.boundaries or {}).items()}
        labels = label_faces(model.faces, selectors, model.tolerance, model.body_names(rough, counter))
        names = {"interface", *labels.values(), *(f.label for f in model.faces if f.label)}
        if any(f.index not in labels and not f.label and len(f.bodies) == 1 for f in model.faces):
            names.add(cad.UNNAMED)
        for what, items in (("supports", scene.supports), ("loads", scene.loads)):
            for i, item in enumerate(items):
                if item.boundary not in names:
                    raise SceneError(f"{what}[{i}].boundary", item.boundary,
                                     "no such boundary in the file's model; labels are " + ", ".join(sorted(names))
                                     + "; name faces with geometry.boundaries.NAME; the faces are\n"
                                     + listing(model.faces, model.body_names(rough, counter)))
        if model.meshed_here:
            self._check_size(scene, model)
        return FileModel(model, rough, counter, labels)

    @staticmethod
    def _check_size(scene, model: TwoBodyModel) -> None:
        """The element estimate of :mod:`ngcontact.scene.mesh_size` on the model's volume and interface."""
        d, unit = scene.discretization, file_length_unit(scene.geometry)
        dim = 3 if scene.geometry.setting == "3d" else 2
        volume = sum(model.volumes) * unit ** dim
        interface = sum(f.area for f in model.interface_faces()) * unit ** (dim - 1)
        width = min(v ** (1 / dim) for v in model.volumes) * unit
        n = mesh_size.estimate(dim, volume, d.maxh, width=width, interface=interface, h_interface=d.interface_maxh)
        mesh_size.refuse_beyond(d.refined_count(n, dim), d.max_elements, *mesh_size.finest_size(d),
                                hint=" or ask for fewer discretization.refinements" if d.refinements else "")

    def build(self, scene, sizes):
        chosen = self.selected(scene)
        return chosen.model.mesh(chosen.rough, chosen.counter, chosen.labels,
                                 length_unit=file_length_unit(scene.geometry), maxh=sizes.maxh,
                                 interface_maxh=sizes.interface_maxh, order=sizes.order)

    def inventory(self, scene):
        chosen = self.selected(scene)
        m = chosen.model
        unit = file_length_unit(scene.geometry)
        lines = [f"{scene.geometry.file}: 2 bodies, {len(m.faces)} faces (lengths in file units; "
                 f"1 unit = {unit:g} m)", m.bodies_listing(), "faces:"]
        named = {f.index: "interface" if len(f.bodies) == 2 else chosen.labels.get(f.index, f.label or cad.UNNAMED)
                 for f in m.faces}
        for f in m.faces:
            lines.append(f"  {f.describe(m.body_names(chosen.rough, chosen.counter))} -> {named[f.index]!r}")
        return lines


MACRO_SHAPES: dict[str, MacroShape] = {"femur_stem": FemurStem(), "coaxial": Coaxial(), "block": Block(),
                                       "file": FromFile()}


def build_geometry(scene, *, maxh=None, interface_maxh=None, order=None, refinements=None) -> gm.MacroGeometry:
    """Mesh the geometry of ``scene`` (sizes, order and ``discretization.refinements`` may be overridden).

    With refinements the mesh is made with straight elements, split
    uniformly (:func:`refined_uniformly`) and curved to the order after the
    last split, as every rank curves its refined part under MPI.
    """
    d = scene.discretization
    maxh = maxh or d.maxh
    times = d.refinements if refinements is None else refinements
    sizes = Sizes(maxh=maxh, interface_maxh=interface_maxh or d.interface_maxh or maxh, order=order or d.order)
    if not times:
        return MACRO_SHAPES[scene.geometry.shape].build(scene, sizes)
    geo = MACRO_SHAPES[scene.geometry.shape].build(scene, replace(sizes, order=1))
    mesh = refined_uniformly(geo.mesh.ngmesh, times)
    if sizes.order > 1:
        mesh.Curve(sizes.order)
    return replace(geo, mesh=mesh)


def refined_uniformly(ngmesh, times: int) -> ng.Mesh:
    """The Netgen mesh ``ngmesh`` split ``times`` times uniformly (Netgen's ``Mesh.Refine``: a triangle into 4,
    a tetrahedron into 8, the new boundary points projected onto its geometry where it has one), as an NGSolve
    mesh.  The same call refines a rank's part of a distributed mesh consistently with its neighbours."""
    for _ in range(times):
        ngmesh.Refine()
    return ng.Mesh(ngmesh)

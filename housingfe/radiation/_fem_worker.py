"""Exterior Helmholtz FE solve with a spherical PML (dolfinx 0.5.2, complex PETSc).

Runs in its own process (`python -m housingfe.radiation._fem_worker job.json result.json`) started by
`housingfe.radiation.fem` with the complex PETSc/SLEPc selected through PETSC_DIR and SLEPC_DIR; the
rest of housingfe runs the real build and one process cannot hold both.

Time convention exp(+i omega t): the momentum equation i omega rho v = -grad p gives, on the vibrating
surface with the body normal n pointing into the air, dp/dn = -i omega rho v_n; the air region's own
outward normal is -n, so the weak form is
    int grad p . grad q* - k^2 p q* dx  =  int i omega rho v_n q* ds.
PML (r > R): complex radial stretch x~ = x (1 - i s(r) / (k r)), s(r) = s_max ((r - R)/d)^2, so an
outgoing wave exp(-i k r) decays like exp(-s(r)) independent of frequency; the weak form becomes
    int (det J J^-1 J^-T grad p) . grad q* - k^2 det J p q* dx,  J = d x~ / d x.
The outer PML boundary and any symmetry plane (the rigid baffle of the piston) are natural (dp/dn = 0).
Without PML (truncation "bgt1"/"bgt2") the air ends at the sphere r = R with a Bayliss-Gunzburger-Turkel
absorbing condition; the PML's frequency-independent decay resolves badly at small kR (see docs/radiation.md).
"""
from __future__ import annotations

import json
import sys
import time

import numpy as np

AIR, PML, VIBRATING, OUTER = 1, 2, 10, 20


def _sphere_model(gmsh, radius, R, d):
    occ = gmsh.model.occ
    body = occ.addSphere(0, 0, 0, radius)
    inner = occ.addSphere(0, 0, 0, R)
    if d > 0:
        outer = occ.addSphere(0, 0, 0, R + d)
        occ.fragment([(3, outer)], [(3, inner), (3, body)])
    else:
        occ.fragment([(3, inner)], [(3, body)])
    occ.synchronize()
    return _classify(gmsh, radius, R, d, half=False, disc=False)


def _piston_model(gmsh, radius, R, d):
    occ = gmsh.model.occ
    inner = occ.addSphere(0, 0, 0, R)
    big = 2.5 * (R + d)
    lower = occ.addBox(-big, -big, -big, 2 * big, 2 * big, big)
    disc = occ.addDisk(0, 0, 0, radius, radius)
    if d > 0:
        outer = occ.addSphere(0, 0, 0, R + d)
        occ.fragment([(3, outer)], [(3, inner)])
    occ.synchronize()
    vols = gmsh.model.getEntities(3)
    occ.cut(vols, [(3, lower)])
    occ.synchronize()
    occ.fragment(gmsh.model.getEntities(3), [(2, disc)])
    occ.synchronize()
    return _classify(gmsh, radius, R, d, half=True, disc=True)


def _box_model(gmsh, box, R):
    """A box body (lx, ly, lz) centred at the origin, air up to the sphere R; all six faces vibrate."""
    occ = gmsh.model.occ
    lx, ly, lz = box
    body = occ.addBox(-lx / 2, -ly / 2, -lz / 2, lx, ly, lz)
    air = occ.addSphere(0, 0, 0, R)
    occ.cut([(3, air)], [(3, body)])
    occ.synchronize()
    vols = gmsh.model.getEntities(3)
    if len(vols) != 1:
        raise RuntimeError(f"box geometry: expected one air volume, got {vols}")
    faces = [t for _, t in gmsh.model.getBoundary(vols, oriented=False)
             if abs(occ.getMass(2, t) - 4 * np.pi * R**2) > 1e-3 * R**2]
    if len(faces) != 6:
        raise RuntimeError(f"box geometry: expected 6 box faces, got {faces}")
    gmsh.model.addPhysicalGroup(3, [vols[0][1]], AIR)
    gmsh.model.addPhysicalGroup(2, faces, VIBRATING)


def _classify(gmsh, radius, R, d, half, disc):
    """Physical groups by measured volume/area: air between the body and R, PML from R to R + d,
    the vibrating surface (sphere of `radius`, or the disc of `radius` on z = 0)."""
    occ = gmsh.model.occ
    factor = 0.5 if half else 1.0
    v_air = factor * 4 / 3 * np.pi * (R**3 - (0 if disc else radius**3))
    v_pml = factor * 4 / 3 * np.pi * ((R + d) ** 3 - R**3)
    air, pml = [], []
    for dim, tag in gmsh.model.getEntities(3):
        vol = occ.getMass(dim, tag)
        if abs(vol - v_air) < 1e-3 * v_air:
            air.append(tag)
        elif abs(vol - v_pml) < 1e-3 * v_pml:
            pml.append(tag)
        else:
            gmsh.model.removeEntities([(dim, tag)], recursive=True)
    target = np.pi * radius**2 if disc else 4 * np.pi * radius**2
    vib = [t for _, t in gmsh.model.getEntities(2)
           if abs(occ.getMass(2, t) - target) < 1e-3 * target
           and np.allclose(occ.getCenterOfMass(2, t), 0.0, atol=1e-6 * radius)]
    if len(air) != 1 or len(pml) != (1 if d > 0 else 0) or len(vib) != 1:
        raise RuntimeError(f"geometry classification failed: air {air}, pml {pml}, vibrating {vib}")
    gmsh.model.addPhysicalGroup(3, air, AIR)
    if pml:
        gmsh.model.addPhysicalGroup(3, pml, PML)
    gmsh.model.addPhysicalGroup(2, vib, VIBRATING)


def build_mesh(geometry: dict, save_msh: str | None = None):
    """Mesh (second-order tets) of a built-in geometry in memory; returns (mesh, cell_tags, facet_tags)."""
    import gmsh
    from dolfinx.io import gmshio
    from mpi4py import MPI

    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("Mesh.RecombineAll", 0)
        gmsh.option.setNumber("Mesh.ElementOrder", 2)
        gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 1)
        gmsh.option.setNumber("Mesh.MeshSizeMax", geometry["h"])
        gmsh.option.setNumber("Mesh.MeshSizeMin", 0.1 * geometry["h"])
        if geometry["kind"] == "msh":
            # A user mesh: physical volume AIR (1) [and PML (2)], physical surface VIBRATING (10), the
            # outer boundary the sphere r = outer_radius (+ pml_thickness) about the origin.
            gmsh.open(geometry["path"])
            return gmshio.model_to_mesh(gmsh.model, MPI.COMM_SELF, 0, gdim=3)
        gmsh.model.add("radiator")
        args = (geometry["radius"], geometry["outer_radius"], geometry["pml_thickness"])
        if geometry["kind"] == "sphere":
            _sphere_model(gmsh, *args)
        elif geometry["kind"] == "box":
            _box_model(gmsh, geometry["box"], geometry["outer_radius"])
        elif geometry["kind"] == "baffled_piston":
            _piston_model(gmsh, *args)
        else:
            raise ValueError(f"unknown geometry kind {geometry['kind']!r}")
        # Finer on the vibrating surface, where the power is integrated.
        surface_h = geometry.get("h_surface", geometry["h"])
        vib = gmsh.model.getEntitiesForPhysicalGroup(2, VIBRATING)
        pts = gmsh.model.getBoundary([(2, t) for t in vib], combined=False, recursive=True)
        gmsh.model.mesh.setSize(pts, surface_h)
        field = gmsh.model.mesh.field
        f_dist = field.add("Distance")
        field.setNumbers(f_dist, "SurfacesList", list(vib))
        f_thr = field.add("Threshold")
        field.setNumber(f_thr, "InField", f_dist)
        field.setNumber(f_thr, "SizeMin", surface_h)
        field.setNumber(f_thr, "SizeMax", geometry["h"])
        field.setNumber(f_thr, "DistMin", 0.0)
        field.setNumber(f_thr, "DistMax", 4 * geometry["h"])
        field.setAsBackgroundMesh(f_thr)
        gmsh.model.mesh.generate(3)
        if save_msh:
            gmsh.write(save_msh)
        return gmshio.model_to_mesh(gmsh.model, MPI.COMM_SELF, 0, gdim=3)
    finally:
        gmsh.finalize()


def _velocity_function(V, facet_tags, velocity: dict):
    """The normal velocity as a function of V: a uniform complex value, or nearest-neighbour values from
    surface samples (points (n,3), values (n,)) at the dofs of the vibrating surface."""
    from dolfinx import fem

    g = fem.Function(V)
    if "uniform" in velocity:
        re, im = velocity["uniform"]
        g.x.array[:] = complex(re, im)
        return g
    from scipy.spatial import cKDTree

    data = np.load(velocity["npz"])
    dofs = fem.locate_dofs_topological(V, 2, facet_tags.find(VIBRATING))
    coords = V.tabulate_dof_coordinates()[dofs]
    _, nearest = cKDTree(data["points"]).query(coords)
    g.x.array[dofs] = data["values"][nearest]
    return g


def _with_outer_boundary(mesh, facet_tags, outer_radius):
    """Facet tags with the outer sphere r = outer_radius added as OUTER (found from the vertices)."""
    from dolfinx import mesh as dmesh

    tol = 1e-6 * outer_radius
    outer = dmesh.locate_entities_boundary(
        mesh, 2, lambda x: np.abs(np.linalg.norm(x, axis=0) - outer_radius) < tol)
    indices = np.concatenate([facet_tags.indices, outer]).astype(np.int32)
    values = np.concatenate([facet_tags.values, np.full(len(outer), OUTER)]).astype(np.int32)
    order = np.argsort(indices)
    return dmesh.meshtags(mesh, 2, indices[order], values[order])


def solve(job: dict) -> dict:
    import ufl
    from dolfinx import fem
    from dolfinx.fem.petsc import LinearProblem
    from petsc4py import PETSc

    assert np.issubdtype(PETSc.ScalarType, np.complexfloating), "needs the complex PETSc build"
    t0 = time.perf_counter()
    truncation = job.get("truncation", "bgt2")
    geometry = dict(job["geometry"])
    if truncation != "pml":
        geometry["pml_thickness"] = 0.0  # the air ends at r = outer_radius
    mesh, cell_tags, facet_tags = build_mesh(geometry, job.get("save_msh"))
    t_mesh = time.perf_counter() - t0

    rho, c = job["rho"], job["c"]
    R, d = geometry["outer_radius"], geometry["pml_thickness"]
    V = fem.FunctionSpace(mesh, ("Lagrange", job.get("degree", 2)))
    p, q = ufl.TrialFunction(V), ufl.TestFunction(V)
    k = fem.Constant(mesh, PETSc.ScalarType(1.0))
    omega_rho = fem.Constant(mesh, PETSc.ScalarType(1.0))
    v_n = _velocity_function(V, facet_tags, job["velocity"])

    dx = ufl.Measure("dx", domain=mesh, subdomain_data=cell_tags)
    facet_tags = _with_outer_boundary(mesh, facet_tags, R + d)
    ds = ufl.Measure("ds", domain=mesh, subdomain_data=facet_tags)
    a = (ufl.inner(ufl.grad(p), ufl.grad(q)) - k**2 * ufl.inner(p, q)) * dx(AIR)
    if truncation == "pml":
        x = ufl.SpatialCoordinate(mesh)
        r = ufl.sqrt(ufl.dot(x, x))
        stretch = job.get("pml_strength", 8.0) * ((r - R) / d) ** 2
        J = ufl.grad(x * (1 - 1j * stretch / (k * r)))
        detJ, invJ = ufl.det(J), ufl.inv(J)
        dx_pml = dx(PML, metadata={"quadrature_degree": job.get("pml_quadrature_degree", 6)})
        a += (ufl.inner(detJ * invJ * invJ.T * ufl.grad(p), ufl.grad(q))
              - k**2 * detJ * ufl.inner(p, q)) * dx_pml
    elif truncation in ("bgt1", "bgt2"):
        # -int dp/dn q* ds with the Bayliss-Gunzburger-Turkel condition on the sphere r = R:
        # dp/dr = -(1/R + i k) p + Lap_G p / (2 (1/R + i k))  (bgt2; bgt1 drops the last term).
        # Exact for the monopole (bgt1) and for monopole + dipole fields (bgt2).
        beta = 1.0 / R + 1j * k
        a += beta * ufl.inner(p, q) * ds(OUTER)
        if truncation == "bgt2":
            n = ufl.FacetNormal(mesh)
            grad_s = lambda u: ufl.grad(u) - ufl.dot(ufl.grad(u), n) * n
            a += 1.0 / (2.0 * beta) * ufl.inner(grad_s(p), grad_s(q)) * ds(OUTER)
    else:
        raise ValueError(f"unknown truncation {truncation!r}")
    L = 1j * omega_rho * ufl.inner(v_n, q) * ds(VIBRATING)

    from housingfe.solvers.mumps import check_solved

    t1 = time.perf_counter()
    problem = LinearProblem(a, L, petsc_options={"ksp_type": "preonly", "pc_type": "lu",
                                                 "pc_factor_mat_solver_type": "mumps"})
    t_compile = time.perf_counter() - t1
    p_h = problem.u
    power_form = fem.form(0.5 * ufl.inner(p_h, v_n) * ds(VIBRATING))
    area = fem.assemble_scalar(fem.form(1.0 * ds(VIBRATING))).real
    mean_square = fem.assemble_scalar(fem.form(0.5 * ufl.inner(v_n, v_n) * ds(VIBRATING))).real / area

    rows = []
    for f in job["frequencies_hz"]:
        t2 = time.perf_counter()
        k.value = 2 * np.pi * f / c
        omega_rho.value = 2 * np.pi * f * rho
        problem.solve()
        check_solved(problem.solver, f"radiation FEM at {f:.6g} Hz")   # a failed MUMPS factor returns garbage
        power = fem.assemble_scalar(power_form).real
        rows.append({"frequency_hz": f, "power_w": power, "sigma": power / (rho * c * area * mean_square),
                     "area_m2": area, "mean_square_velocity": mean_square,
                     "seconds": time.perf_counter() - t2})
    return {"ndofs": V.dofmap.index_map.size_global, "ncells": mesh.topology.index_map(3).size_global,
            "mesh_seconds": t_mesh, "setup_seconds": t_compile, "results": rows}


def main(argv: list[str]) -> int:
    job_path, result_path = argv
    with open(job_path) as fh:
        job = json.load(fh)
    result = solve(job)
    with open(result_path, "w") as fh:
        json.dump(result, fh)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))

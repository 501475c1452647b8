"""beamfx.startup: what the command does before the stack's imports."""

import sys

from beamfx import startup


def test_a_singleton_asks_for_ob1_and_no_daemon_and_mpirun_or_the_user_keep_theirs():
    env = {}
    assert startup.mpi_singleton(env)
    assert env == {"OMPI_MCA_pml": "ob1", "OMPI_MCA_ess_singleton_isolated": "1"}
    launches = ({"OMPI_COMM_WORLD_SIZE": "2"}, {"PMIX_RANK": "0"}, {"PMI_RANK": "1"})
    for launched in (*launches, {"SLURM_PROCID": "0"}):
        env = dict(launched)
        assert not startup.mpi_singleton(env) and env == launched
    env = {"OMPI_MCA_pml": "ucx"}  # the user's choice kept, the other still asked for
    assert startup.mpi_singleton(env)
    assert env == {"OMPI_MCA_pml": "ucx", "OMPI_MCA_ess_singleton_isolated": "1"}
    mine = {"OMPI_MCA_pml": "ucx", "OMPI_MCA_ess_singleton_isolated": "0"}
    env = dict(mine)
    assert not startup.mpi_singleton(env) and env == mine


def test_a_singletons_child_is_a_singleton_not_a_second_rank_0():
    """What a singleton's MPI start exports (its job's PMIx namespace, rank 0) is dropped by
    a process it starts; an mpirun-launched rank keeps its own."""
    child = {
        "OMPI_MCA_ess": "singleton",
        "PMIX_RANK": "0",
        "PMIX_NAMESPACE": "123@0",
        "PMIX_SERVER_URI4": "x",
        "PMIX_MCA_psec": "native",
        "OMPI_MCA_orte_launch": "1",
        "OMPI_APP_CTX_NUM_PROCS": "1",
    }
    assert startup.mpi_singleton(child)
    assert child == {
        "PMIX_MCA_psec": "native",
        "OMPI_MCA_pml": "ob1",
        "OMPI_MCA_ess_singleton_isolated": "1",
    }
    rank = {"OMPI_MCA_ess": "^singleton", "PMIX_RANK": "1", "OMPI_COMM_WORLD_SIZE": "2"}
    assert not startup.mpi_singleton(dict(rank))


def test_an_isolated_singleton_runs_mpi_and_io(tmp_path):
    """A singleton without OpenMPI's support daemon still does what a run does: collectives,
    and MPI-IO through HDF5 (the XDMF output)."""
    import os
    import subprocess

    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_"))}
    startup.mpi_singleton(env)
    code = (
        "from mpi4py import MPI; import dolfinx.io, dolfinx.mesh; c = MPI.COMM_WORLD; "
        "m = dolfinx.mesh.create_unit_interval(c, 4); "
        f"f = dolfinx.io.XDMFFile(c, {str(tmp_path / 'm.xdmf')!r}, 'w'); f.write_mesh(m); "
        "f.close(); print(c.size, c.allreduce(2))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code],
        check=False,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["1", "2"] and (tmp_path / "m.h5").stat().st_size > 0


def test_ufl_and_ffcx_versions_are_read_as_pkg_resources_reads_them(monkeypatch):
    """The stand-in answers UFL's and FFCx's own version as the real module does; any other
    question loads the real module, which then takes its place."""
    import importlib.metadata

    for name, package in startup.OWN_VERSION.items():
        assert startup.dist_info_version(name, package) == importlib.metadata.version(name)
    monkeypatch.delitem(sys.modules, "pkg_resources", raising=False)
    assert startup.light_versions()
    stand_in = sys.modules["pkg_resources"]
    assert isinstance(stand_in, startup._VersionsOnly)
    assert not startup.light_versions()  # in place already: left alone
    version = stand_in.get_distribution("fenics-ufl").version
    assert version == importlib.metadata.version("fenics-ufl")
    assert "pkg_resources" in sys.modules and sys.modules["pkg_resources"] is stand_in
    numpy = stand_in.get_distribution("numpy")  # not one of the two: the real answer
    assert numpy.version == importlib.metadata.version("numpy") and hasattr(numpy, "location")
    real = sys.modules["pkg_resources"]
    assert real is not stand_in and stand_in.working_set is real.working_set


def test_a_distribution_without_metadata_has_no_version_here():
    assert startup.dist_info_version("no-such-dist", "beamfx") is None
    assert startup.dist_info_version("no-such-dist", "no_such_package_here") is None


def test_a_bench_process_imports_only_the_module_of_its_case():
    """``beamfx.bench.process`` runs one setting after importing the module that registered
    its case, not every paper's (some compute their theory at import)."""
    from beamfx.bench import all_cases
    from beamfx.bench.registry import REGISTERED_IN

    cases = all_cases()
    assert REGISTERED_IN["rollup_0.5"] == "beamfx.bench.classic"
    assert REGISTERED_IN["spin_up_time"] == "beamfx.bench.transient"
    assert set(REGISTERED_IN) == set(cases)
    assert all(m.startswith("beamfx.bench.") and m in sys.modules for m in REGISTERED_IN.values())


def test_the_compiler_log_is_quieted_unless_the_user_chose(monkeypatch):
    """SETUPTOOLS_USE_DISTUTILS=stdlib where nobody set it and distutils is still to come."""
    monkeypatch.delitem(sys.modules, "distutils", raising=False)
    env = {}
    assert startup.quiet_compiler(env) and env == {"SETUPTOOLS_USE_DISTUTILS": "stdlib"}
    mine = {"SETUPTOOLS_USE_DISTUTILS": "local"}
    assert not startup.quiet_compiler(mine) and mine == {"SETUPTOOLS_USE_DISTUTILS": "local"}

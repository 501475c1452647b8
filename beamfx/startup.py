"""What the ``beamfx`` command does before the stack's imports, so that a run starts sooner.

Two fixed costs of every process, measured on the 2-core Debian 12 machine:

- **OpenMPI's start** (``from mpi4py import MPI``) takes 0.39 s: 0.2 s of it choosing a
  point-to-point layer (the default probes the network ones: UCX, OFI, PSM2), 0.12 s starting
  a support daemon (``orted``) that only ``MPI_Comm_spawn`` would use. A process not launched
  by ``mpirun`` is a singleton, one rank with nobody to talk to and nothing to spawn (beamfx
  never spawns), so :func:`mpi_singleton` asks for OpenMPI's plain ``ob1`` layer and no
  daemon (``ess_singleton_isolated``) there: 0.06 s in all. Under ``mpirun`` nothing is
  changed, and neither is a setting the user made.
- **pkg_resources** (setuptools, ~0.1 s: it scans every installed distribution) is imported
  by UFL 2022.2 and FFCx 0.5 only to read their own version. :func:`light_versions` puts a
  stand-in in its place that reads those two versions from their ``.dist-info`` and loads the
  real module the moment anything else is asked of it.

And the JIT's C builds go through Python's own ``distutils`` (:func:`quiet_compiler`), whose
build log is silent, as under the Makefile.

Only the command line does this (:func:`beamfx.cli.main`); ``import beamfx`` changes nothing.
"""

import os
import sys
import types
from pathlib import Path

#: the distributions whose version the stand-in answers, and their top-level package
OWN_VERSION = {"fenics-ufl": "ufl", "fenics-ffcx": "ffcx"}
#: environment variables that a launcher sets in each rank: OpenMPI's mpirun (PRRTE/PMIx),
#: Slurm's srun (PMI-2 or PMIx; SLURM_PROCID also in a batch script's own step, where asking
#: for nothing only costs the faster start)
LAUNCHED = ("OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "OMPI_MCA_ess", "PMI_RANK", "SLURM_PROCID")


#: what a singleton asks of OpenMPI (each unless the user set it): the ``ob1``
#: point-to-point layer, and no support daemon (it serves only MPI_Comm_spawn)
SINGLETON = {"OMPI_MCA_pml": "ob1", "OMPI_MCA_ess_singleton_isolated": "1"}


#: what a singleton's MPI start exports to the processes it starts (``OMPI_MCA_ess`` is then
#: ``singleton``; without ``ess_singleton_isolated`` also the ``PMIX_*`` of its daemon, with
#: ``PMIX_RANK`` = 0): a child that kept them would join its parent's job as a second rank 0
INHERITED = (
    "OMPI_MCA_ess",
    "OMPI_MCA_pmix",
    "OMPI_MCA_orte_ess_num_procs",
    "OMPI_MCA_orte_launch",
    "OMPI_MCA_orte_precondition_transports",
    "OMPI_APP_CTX_NUM_PROCS",
)


def mpi_singleton(env=os.environ):
    """Set :data:`SINGLETON`'s variables the user has not set in a process not started by
    ``mpirun``; True if any was set. A process started by a singleton (a Python script with
    mpi4py that runs ``beamfx``) drops what that one exported (:data:`INHERITED`, ``PMIX_*``
    but ``PMIX_MCA_*``): it was not launched, and joining the parent's job made its start
    twice as slow (0.8 against 0.4 s for a small run)."""
    if env.get("OMPI_MCA_ess") == "singleton":
        pmix = [k for k in env if k.startswith("PMIX_") and not k.startswith("PMIX_MCA_")]
        for k in [*pmix, *(k for k in INHERITED if k in env)]:
            del env[k]
    if any(k in env for k in LAUNCHED):
        return False
    unset = {k: v for k, v in SINGLETON.items() if k not in env}
    env.update(unset)
    return bool(unset)


def dist_info_version(name, package):
    """The ``Version:`` of distribution ``name`` from the ``.dist-info`` (or ``.egg-info``)
    beside its top-level ``package``, without importing it; None if there is none."""
    from importlib.util import find_spec

    spec = find_spec(package)
    if spec is None or spec.origin is None:
        return None
    folder, stem = Path(spec.origin).parent.parent, name.replace("-", "_")
    for meta in (
        *folder.glob(f"{stem}-*.dist-info/METADATA"),
        *folder.glob(f"{stem}-*.egg-info/PKG-INFO"),
    ):
        for line in meta.read_text(errors="replace").splitlines():
            if line.startswith("Version:"):
                return line.split(":", 1)[1].strip()
            if not line:  # the headers end at the first empty line
                break
    return None


def _real():
    """The real ``pkg_resources``, imported in place of the stand-in."""
    if isinstance(sys.modules.get("pkg_resources"), _VersionsOnly):
        del sys.modules["pkg_resources"]
    import pkg_resources

    return pkg_resources


class _VersionsOnly(types.ModuleType):
    """``pkg_resources`` for UFL and FFCx: ``get_distribution(name).version`` of
    :data:`OWN_VERSION`'s names, once each (their import's question); every other name or
    attribute, and any later question, from the real module. Once both are answered it leaves
    ``sys.modules``: a later ``import pkg_resources`` gets the real module."""

    def __init__(self, name):
        super().__init__(name)
        self._unread = set(OWN_VERSION)

    def get_distribution(self, name):
        version = None
        if name in self._unread:
            self._unread.discard(name)
            version = dist_info_version(name, OWN_VERSION[name])
            if not self._unread and sys.modules.get("pkg_resources") is self:
                del sys.modules["pkg_resources"]
        if version is None:
            return _real().get_distribution(name)
        return types.SimpleNamespace(project_name=name, version=version)

    def __getattr__(self, attr):
        return getattr(_real(), attr)


def light_versions():
    """Put the stand-in for ``pkg_resources`` in place unless it is imported already; True if
    it was."""
    from importlib.util import find_spec

    if "pkg_resources" in sys.modules:
        return False
    spec = find_spec("pkg_resources")  # where the real one is (None: not installed)
    if spec is None:
        return False
    stand_in = _VersionsOnly("pkg_resources")
    stand_in.__spec__ = spec  # as find_spec and importlib see the real module
    sys.modules["pkg_resources"] = stand_in
    return True


def quiet_compiler(env=os.environ):
    """Python's own ``distutils`` for the JIT's C builds (``SETUPTOOLS_USE_DISTUTILS=stdlib``,
    what the Makefile sets), unless the user chose or ``distutils`` is imported already:
    through setuptools' copy, cffi's build logged ``running build_ext`` and every ``gcc``
    line at INFO on the root logger, 20-30 lines on stderr per compiled scene. Its import
    hook, installed at the interpreter's start by setuptools' ``.pth``, is taken out. True
    if it was set."""
    if "SETUPTOOLS_USE_DISTUTILS" in env or "distutils" in sys.modules:
        return False
    env["SETUPTOOLS_USE_DISTUTILS"] = "stdlib"
    hack = sys.modules.get("_distutils_hack")
    if hack is not None and hasattr(hack, "remove_shim"):
        hack.remove_shim()
    return True


def prepare():
    """All three, before anything imports mpi4py, UFL, FFCx or distutils
    (:func:`beamfx.cli.main`); the
    stand-in only while UFL or FFCx is still to be imported (a second ``main`` in one process,
    a test's, has nothing to save and would leave it in place)."""
    mpi_singleton()
    quiet_compiler()
    if not all(package in sys.modules for package in OWN_VERSION.values()):
        light_versions()

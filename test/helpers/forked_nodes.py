"""Run a node's ``main()`` the way ``python -m MODULE --ros-args ...`` does, in a child forked from a
forkserver that imported the node modules once (``multiprocessing`` forkserver preload): the same
module, argv, environment, stdout/stderr file descriptors and exit code, without paying the
interpreter start and the imports (1-2 s of CPU) for each of the hostile-parameter cases."""
from __future__ import annotations

import importlib
import multiprocessing
import os
import subprocess
import sys

NODE_MODULES = ("att_sim.truth.simulator_node", "att_planner.nodes.controller_node", "att_planner.nodes.estimator_node",
                "att_planner.nodes.planner_node", "att_msgs_py.log.recorder_node")


def _run(module: str, args: list, env: dict, output_path: str) -> None:
    """The child: stdout and stderr (file descriptors 1 and 2, so rcl's C logging too) to
    ``output_path``, ``sys.argv`` as ``-m`` sets it, then the module's ``main()``."""
    fd = os.open(output_path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
    os.dup2(fd, 1)
    os.dup2(fd, 2)
    os.environ.clear()
    os.environ.update(env)
    mod = importlib.import_module(module)
    sys.argv = [mod.__file__, "--ros-args", *args]
    try:
        mod.main()
    finally:
        sys.stdout.flush()
        sys.stderr.flush()


def context() -> multiprocessing.context.BaseContext:
    ctx = multiprocessing.get_context("forkserver")
    ctx.set_forkserver_preload(list(NODE_MODULES))
    return ctx


def run_case(ctx, module: str, args: list, env: dict, output_path: str,
             timeout: float = 30.0) -> tuple[int | None, str]:
    """Exit code (None: still running after ``timeout`` s, then killed) and the output. The exit
    code is the forkserver's report. Where it reports 255 — also its "status lost" (CPython's
    ``popen_forkserver.poll`` when the status pipe gives EOF, seen once under load) — the case is run
    again as ``python -m MODULE --ros-args ...`` and that process's own exit status and output are
    taken: no status the child reports about itself is trusted."""
    proc = ctx.Process(target=_run, args=(module, args, env, output_path))
    proc.start()
    proc.join(timeout)
    code = proc.exitcode
    if code is None:
        proc.kill()
        proc.join()
    elif code == 255:
        code = _run_as_process(module, args, env, output_path, timeout)
    with open(output_path, encoding="utf-8", errors="replace") as fh:
        return code, fh.read()


def _run_as_process(module: str, args: list, env: dict, output_path: str, timeout: float) -> int | None:
    """Exit code of ``python -m module --ros-args *args`` (None: killed after ``timeout`` s), its
    output in ``output_path``."""
    with open(output_path, "wb") as out:
        try:
            return subprocess.run([sys.executable, "-m", module, "--ros-args", *args], env=env, stdout=out,
                                  stderr=subprocess.STDOUT, timeout=timeout).returncode
        except subprocess.TimeoutExpired:
            return None

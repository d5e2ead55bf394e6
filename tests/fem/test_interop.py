"""NGSolve and PyTorch in one process (the FEM campaign feeds the surrogates)."""

import subprocess
import sys
import textwrap


def test_pytorch_runs_after_an_fem_sweep_in_the_same_process():
    # NGSolve loaded before PyTorch made batched matrix products segfault;
    # softbend.fem loads PyTorch first. A crash shows as a negative return code.
    script = textwrap.dedent(
        """
        from softbend.design import parse_sfrba
        from softbend.fem import FEMOptions, simulate

        simulate(parse_sfrba("100,6,2,2,5,10"), [0.0, 0.005], FEMOptions(maxh_mm=6))
        import torch

        a, b = torch.randn(64, 200, 50), torch.randn(64, 50, 60)
        for _ in range(20):
            torch.baddbmm(torch.zeros(64, 200, 60), a, b).tanh_()
        print("ok")
        """
    )
    run = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=300
    )
    assert run.returncode == 0, run.stderr[-2000:]
    assert run.stdout.strip().endswith("ok")

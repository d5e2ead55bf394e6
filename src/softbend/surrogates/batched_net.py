"""M padded two-hidden-layer tanh networks trained as one tensor program.

:class:`BatchedMLP` holds the weights of M small MLPs in padded tensors of shape
(M, d, H1max), (M, H1max, H2max) and (M, H2max, 1); every forward and backward
product is one ``torch.baddbmm``/``torch.bmm`` over the model axis. Hidden units
beyond a model's own size have zero incoming and outgoing weights and bias: their
activation is tanh(0) = 0, so they contribute nothing to the output, their
gradients are exactly zero, and Adam (zero gradient, zero moments) leaves them at
zero. No mask is needed (a mask would cost two passes over every activation
tensor per product). Gradients are written by hand
(three layers, closed form), not by autograd: that keeps memory at one set of
activations. The update is Adam written as batched
tensor operations (betas 0.9/0.999, eps 1e-8, bias correction; the update of
:class:`torch.optim.Adam`) with a per-model step count and a per-model *active*
mask. :func:`softbend.surrogates.batched.train_mlp_grid` drives it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from softbend._torch import require_torch

if TYPE_CHECKING:
    import torch
else:
    torch = require_torch("the MLP surrogate (softbend.surrogates)")

__all__ = ["BatchedMLP"]

_BETA1 = 0.9
_BETA2 = 0.999
_EPS = 1e-8


class BatchedMLP:
    """M padded two-hidden-layer tanh networks with hand-written backward pass and Adam.

    Parameters are tensors ``W[l]`` of shape (M, fan_in, fan_out) and biases
    ``b[l]`` of shape (M, 1, fan_out), zero on padding (the rows and columns of
    hidden units beyond a model's own size), where they stay: see the module notes.
    """

    def __init__(
        self,
        coefs: Sequence[Sequence[np.ndarray]],
        intercepts: Sequence[Sequence[np.ndarray]],
        h1_max: int,
        h2_max: int,
        *,
        device: str,
        dtype: torch.dtype,
    ) -> None:
        n_models = len(coefs)
        d = coefs[0][0].shape[0]
        shapes = ((d, h1_max), (h1_max, h2_max), (h2_max, 1))
        W = [np.zeros((n_models, *s)) for s in shapes]
        b = [np.zeros((n_models, 1, s[1])) for s in shapes]
        for m in range(n_models):
            for layer in range(3):
                rows, cols = coefs[m][layer].shape
                W[layer][m, :rows, :cols] = coefs[m][layer]
                b[layer][m, 0, :cols] = intercepts[m][layer]

        def tensor(a: np.ndarray) -> torch.Tensor:
            return torch.tensor(a, dtype=dtype, device=device)

        self.params = [tensor(W[0]), tensor(b[0]), tensor(W[1]), tensor(b[1])]
        self.params += [tensor(W[2]), tensor(b[2])]
        self.exp_avg = [torch.zeros_like(p) for p in self.params]
        self.exp_avg_sq = [torch.zeros_like(p) for p in self.params]
        self.steps = torch.zeros(n_models, dtype=torch.float64, device=device)

    def forward(self, Z: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Hidden activations A1 (M, B, H1), A2 (M, B, H2) and output (M, B)."""
        W1, b1, W2, b2, W3, b3 = self.params
        A1 = torch.baddbmm(b1, Z, W1).tanh_()
        A2 = torch.baddbmm(b2, A1, W2).tanh_()
        out = torch.baddbmm(b3, A2, W3).squeeze(-1)
        return A1, A2, out

    def gradients(
        self, Z: torch.Tensor, target: torch.Tensor, weight: torch.Tensor, count: torch.Tensor
    ) -> tuple[list[torch.Tensor], torch.Tensor]:
        """Gradients of each model's mean squared error and its sum of squared errors.

        ``weight`` (M, B) is 1 for a real row and 0 for padding; ``count`` (M,) is the
        model's number of real rows (clamped to >= 1).
        """
        W2, W3 = self.params[2], self.params[4]
        A1, A2, out = self.forward(Z)
        residual = (out - target).mul_(weight)
        sse = (residual * residual).sum(dim=1)
        G = residual.mul_((2.0 / count).unsqueeze(1)).unsqueeze(-1)  # (M, B, 1)
        gW3 = torch.bmm(A2.transpose(1, 2), G)
        gb3 = G.sum(dim=1, keepdim=True)
        dP2 = G * W3.transpose(1, 2)  # (M, B, H2); zero on padded units (W3 is zero there)
        dP2.mul_(torch.square(A2).neg_().add_(1.0))
        gW2 = torch.bmm(A1.transpose(1, 2), dP2)
        gb2 = dP2.sum(dim=1, keepdim=True)
        dP1 = torch.bmm(dP2, W2.transpose(1, 2))  # zero on padded units (rows of W2 zero)
        dP1.mul_(torch.square(A1).neg_().add_(1.0))
        gW1 = torch.bmm(Z.transpose(1, 2), dP1)
        gb1 = dP1.sum(dim=1, keepdim=True)
        return [gW1, gb1, gW2, gb2, gW3, gb3], sse

    def adam_step(
        self,
        grads: list[torch.Tensor],
        active: torch.Tensor,
        lr: float,
        *,
        all_active: bool = False,
    ) -> None:
        """One Adam update (torch.optim.Adam's formula) of the active models only.

        ``all_active``: the caller knows every model is active, so the update is
        done in place, without selecting between old and new values (the same
        arithmetic, bitwise the same result, fewer tensor operations).
        """
        self.steps += active.to(torch.float64)
        steps = self.steps.clamp(min=1.0)
        step_size = lr / (1.0 - _BETA1**steps)
        bc2_sqrt = torch.sqrt(1.0 - _BETA2**steps)
        dtype = self.params[0].dtype
        step_size = step_size.to(dtype).view(-1, 1, 1)
        bc2_sqrt = bc2_sqrt.to(dtype).view(-1, 1, 1)
        if all_active:
            for p, m, v, g in zip(self.params, self.exp_avg, self.exp_avg_sq, grads, strict=True):
                m.lerp_(g, 1.0 - _BETA1)
                v.mul_(_BETA2).addcmul_(g, g, value=1.0 - _BETA2)
                denom = (v.sqrt() / bc2_sqrt).add_(_EPS)
                p.sub_(step_size * m / denom)
            return
        keep = active.view(-1, 1, 1)
        for p, m, v, g in zip(self.params, self.exp_avg, self.exp_avg_sq, grads, strict=True):
            m_new = torch.lerp(m, g, 1.0 - _BETA1)
            v_new = (v * _BETA2).addcmul_(g, g, value=1.0 - _BETA2)
            denom = (v_new.sqrt() / bc2_sqrt).add_(_EPS)
            p_new = p - step_size * m_new / denom
            m.copy_(torch.where(keep, m_new, m))
            v.copy_(torch.where(keep, v_new, v))
            p.copy_(torch.where(keep, p_new, p))

    def train_step(
        self,
        Z: torch.Tensor,
        target: torch.Tensor,
        weight: torch.Tensor,
        count: torch.Tensor,
        active: torch.Tensor,
        lr: float,
        all_active: bool,
    ) -> torch.Tensor:
        """One mini-batch: gradients (:meth:`gradients`), then Adam (:meth:`adam_step`).

        Returns each model's sum of squared errors before the update, (M,). One
        function, so that it can be compiled (``torch.compile``) as a whole.
        """
        grads, sse = self.gradients(Z, target, weight, count)
        self.adam_step(grads, active, lr, all_active=all_active)
        return sse

    def extract(self, m: int, h1: int, h2: int) -> tuple[list[np.ndarray], list[np.ndarray]]:
        """Model ``m``'s parameters, unpadded, as float64 arrays (contract shapes)."""
        W1, b1, W2, b2, W3, b3 = (p[m].detach().to("cpu", torch.float64) for p in self.params)
        coefs = [W1[:, :h1].numpy().copy(), W2[:h1, :h2].numpy().copy()]
        coefs.append(W3[:h2, :].numpy().copy())
        intercepts = [b1[0, :h1].numpy().copy(), b2[0, :h2].numpy().copy()]
        intercepts.append(b3[0, :].numpy().copy())
        return coefs, intercepts

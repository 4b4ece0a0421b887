"""Selective state space layers (Mamba, Gu & Dao 2023) with the scans our three methods use.

The recurrence, per channel d and state n (zero-order-hold discretisation, A diagonal):

    h_t = exp(delta_t * A) * h_{t-1} + delta_t * B_t * u_t        (Abar, Bbar)
    y_t = <C_t, h_t> + D * u_t

Five implementations of the scan, all differentiable and tested equal:

- ``scan_sequential``: the loop above, one time step at a time. The reference.
- ``scan_parallel``: Hillis-Steele log-depth prefix scan over the affine maps
  h -> a*h + b. ceil(log2 L) rounds of whole-tensor ops; never divides, so always stable.
- ``scan_chunked``: within chunks of K steps the state is a weighted cumulative sum in log
  space, h_t = exp(c_t) * (h_0 + sum_{s<=t} exp(-c_s) * b_s) with c the running sum of
  delta*A; chunks run in a loop carrying h_0. exp(-c_s) grows with the decay inside a
  chunk, so K is chosen from the data so that it stays below exp(60) in float32 (exp(600) in
  float64): exact, never clamped.

- ``scan_compiled`` (``scan_compiled.py``): the loop compiled by numba, with its own
  backward; on the CPU it replaces thousands of small tensor ops per call.
- ``scan_triton`` (``scan_triton.py``): the same loop as one fused Triton kernel, with its
  own backward; the GPU's.

``selective_scan`` picks the compiled scan on the CPU when numba imports, else one of the
eager three (see ``choose_scan``); on a GPU the CUDA kernel of the optional ``mamba-ssm``
package when it imports, else the Triton kernel (float32, power-of-two state sizes), else
the chunked scan.

``SelectiveSSM`` holds k isolated scans over one input (each with its own Conv1D, x/dt
projections, A and D), optionally some of them run on the time-reversed input. That one
module is Motion Mamba's HTM (k forward scans), BSM and KMM's bidirectional layers
(one forward + one backward scan) and a plain Mamba layer (k = 1).
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass

import torch
import torch.nn.functional as F
from torch import nn

from . import scan_compiled as _compiled
from . import scan_triton as _triton
from .causal_conv import causal_conv
from .scan_compiled import STATE_EPS, scan_compiled
from .scan_triton import scan_triton
from .ssm_fused import applies as _fused_applies
from .ssm_fused import fused_ssm

SCANS = ("sequential", "parallel", "chunked", "compiled", "triton")
# exp(-c) inside a chunk stays below exp(limit): float32 overflows at exp(88), float64 at exp(709).
_MAX_LOG_RANGE = {torch.float32: 60.0, torch.float64: 600.0}


def _expand_groups(m: torch.Tensor, d: int) -> torch.Tensor:
    """(B, L, G, N) -> (B, L, D, N): group g serves channels [g*D/G, (g+1)*D/G)."""
    g = m.shape[2]
    if d % g:
        raise ValueError(f"{d} channels cannot be split into {g} groups")
    return m.repeat_interleave(d // g, dim=2)


def _discretise(
    u: torch.Tensor, delta: torch.Tensor, A: torch.Tensor, Bm: torch.Tensor
) -> tuple[torch.Tensor, torch.Tensor]:
    """log(Abar) = delta*A and Bbar*u = delta*B*u, both (B, L, D, N)."""
    # contiguous inputs matter: broadcasting over permuted strides (einsum outputs) made
    # these element-wise ops ~20x slower on CPU
    delta, u = delta.contiguous(), u.contiguous()
    log_a = delta.unsqueeze(-1) * A
    bu = (delta * u).unsqueeze(-1) * _expand_groups(Bm.contiguous(), u.shape[-1])
    return log_a, bu


def _readout(h: torch.Tensor, u: torch.Tensor, Cm: torch.Tensor, D: torch.Tensor | None) -> torch.Tensor:
    y = (h * _expand_groups(Cm, u.shape[-1])).sum(-1)
    return y if D is None else y + u * D


def scan_sequential(u, delta, A, Bm, Cm, D=None):
    """Reference selective scan, one step at a time.

    u, delta: (B, L, D); A: (D, N), or (B, L, D, N) for a state matrix that varies per
    sample and step (FTMoMamba's FreqSSM), negative real parts; Bm, Cm: (B, L, G, N) with
    G | D; D: (D,) or None. Returns y: (B, L, D).
    """
    d = u.shape[-1]
    h = u.new_zeros(u.shape[0], d, A.shape[-1])
    # the inputs are split into per-step views once: indexing delta[:, t] inside the loop
    # made autograd's backward allocate and zero-fill a full (B, L, D) gradient for every
    # step (O(L^2) memory traffic, 60% of a KMM training step); unbind's backward stacks once
    A_t = [A] * u.shape[1] if A.dim() == 2 else A.unbind(1)
    ys = []
    for dt, ut, At, bt, ct in zip(delta.unbind(1), u.unbind(1), A_t, Bm.unbind(1), Cm.unbind(1), strict=True):
        # discretised per step: never holds a (B, L, D, N) tensor
        a = torch.exp(dt[..., None] * At)
        bu = (dt * ut)[..., None] * _expand_groups(bt[:, None], d)[:, 0]
        h = a * h + bu
        ys.append((h * _expand_groups(ct[:, None], d)[:, 0]).sum(-1))
    y = torch.stack(ys, dim=1)
    return y if D is None else y + u * D


def scan_parallel(u, delta, A, Bm, Cm, D=None):
    """Hillis-Steele log-depth scan; same arguments and result as ``scan_sequential``."""
    log_a, b = _discretise(u, delta, A, Bm)
    a = torch.exp(log_a)
    L = u.shape[1]
    k = 1
    while k < L:
        # compose step t with the prefix ending k steps earlier: (a, b) o (a', b') = (a a', a b' + b)
        b = torch.cat([b[:, :k], a[:, k:] * b[:, :-k] + b[:, k:]], dim=1)
        a = torch.cat([a[:, :k], a[:, k:] * a[:, :-k]], dim=1)
        k *= 2
    return _readout(b, u, Cm, D)


def chunk_size_for(delta: torch.Tensor, A: torch.Tensor, limit: float | None = None) -> int:
    """Longest chunk whose summed decay |sum_t delta_t * A| stays below ``limit`` nats for
    every channel and state within every chunk: the whole sequence when it can, else the
    largest power of two that keeps each chunk under the limit. Checked chunk by chunk, not
    from the average: a trained model's decay can sit in a few steps (KMM's did: 233 nats
    over 125 tokens, most of it in one 32-token chunk, and exp(-c) overflowed)."""
    L = delta.shape[1]
    limit = limit or _MAX_LOG_RANGE.get(delta.dtype, 60.0)
    if not delta.numel() or L == 1:
        return max(L, 1)
    d = delta.detach()
    if A.dim() == 2:
        rate = d * (-A.detach()).amax(-1)  # (B, L, D): the steepest state of each channel
    else:  # per-step A (B, L, D, N)
        rate = (d.unsqueeze(-1) * -A.detach()).amax(-1)
    cum = torch.nn.functional.pad(rate.cumsum(1), (0, 0, 1, 0))  # (B, L + 1, D), cum[:, t] = sum of steps < t
    k = L
    while k > 1:
        starts = torch.arange(0, L, k)
        ends = (starts + k).clamp(max=L)
        if float((cum[:, ends] - cum[:, starts]).amax()) <= limit:
            return k
        k = 1 << ((k - 1).bit_length() - 1)  # the next power of two below k
    return 1


_TRIL_MAX = 64
_TRIL: dict[tuple[int, torch.dtype, torch.device], torch.Tensor] = {}


def _cumsum_time(x: torch.Tensor) -> torch.Tensor:
    """Cumulative sum over dim 1 of (B, K, D, N). Up to 64 steps as one matrix product with a
    lower-triangular ones matrix: torch.cumsum over a non-innermost axis runs 3-5x slower on
    our CPU for the short chunks of the denoisers and KMM (README scan table); the sum order
    differs, so results agree to float rounding (the scan tests hold to 1e-5)."""
    K = x.shape[1]
    if K > _TRIL_MAX or K < 2:
        return torch.cumsum(x, dim=1)
    key = (K, x.dtype, x.device)
    if key not in _TRIL:
        _TRIL[key] = torch.ones(K, K, dtype=x.dtype, device=x.device).tril_()
    b, _, d, n = x.shape
    return torch.matmul(_TRIL[key], x.reshape(b, K, d * n)).view(b, K, d, n)


def scan_chunked(u, delta, A, Bm, Cm, D=None, chunk: int | None = None):
    """Chunked log-space scan; same arguments and result as ``scan_sequential``.

    For the short, narrow scans of our denoisers one chunk is often the whole sequence,
    i.e. a handful of whole-tensor ops instead of L steps. Chunks run one after another,
    each on (B, K, D, N), so the full (B, L, D, N) tensor is never built at once.
    """
    L = u.shape[1]
    k = min(chunk or chunk_size_for(delta, A), L)
    if k == 1 and chunk is None:
        # a single step already decays by more than exp(-limit): exp(-c) would overflow, and
        # one-step chunks are the loop anyway (FreqSSM's injected A can get this steep)
        return scan_sequential(u, delta, A, Bm, Cm, D)
    h0 = None
    ys = []
    for s in range(0, L, k):
        sl = slice(s, s + k)
        log_a, bu = _discretise(u[:, sl], delta[:, sl], A if A.dim() == 2 else A[:, sl], Bm[:, sl])
        c = _cumsum_time(log_a)  # (B, K, D, N), <= 0 and decreasing
        decay = torch.exp(c)
        h = decay * _cumsum_time(torch.exp(-c) * bu)
        if h0 is not None:
            h = h + decay * h0.unsqueeze(1)
        h0 = h[:, -1]
        ys.append(_readout(h, u[:, sl], Cm[:, sl], None))
    y = torch.cat(ys, dim=1)
    return y if D is None else y + u * D


_IMPLS = {
    "sequential": scan_sequential,
    "parallel": scan_parallel,
    "chunked": scan_chunked,
    "compiled": scan_compiled,
    "triton": scan_triton,
}


def choose_scan(length: int, state_numel: int, grad: bool = False) -> str:
    """The CPU scan for a length and a state size B*D*N, from
    ``python -m motion_core.eval bench --scans`` on our 2-core machine (README table): the loop
    for very short scans and for big states (memory traffic dominates, and the loop never
    holds (B, L, D, N)); the chunked log-space scan for small states over long sequences,
    where a handful of whole-tensor ops replace L loop steps (BSM's scan over channels).
    With ``grad`` (the scan will be differentiated) the loop wins from half that size: the
    chunked scan's backward goes through its (B, K, D, N) exp / cumsum tensors again, the
    loop's through (B, D, N) steps (forward + backward at B 32, L 50, D 128, N 8: loop 61 ms,
    chunked 111 ms; at L*B*D*N = 1M, chunked 59 ms against the loop's 250)."""
    if length <= 8:
        return "sequential"
    limit = (1 << 20) if grad else (1 << 21)
    return "chunked" if state_numel * length <= limit else "sequential"


def _cuda_scan():
    try:
        from mamba_ssm.ops.selective_scan_interface import selective_scan_fn  # type: ignore
    except Exception:  # optional dependency; any import failure means "not available"
        return None
    return selective_scan_fn


_FORCED_SCAN: str | None = None
_COMPILED_OFF = False
_STATE_UPDATES: list[int] | None = None


@contextmanager
def eager_scans() -> Iterator[None]:
    """Inside the block the dispatcher ignores the compiled scan and picks among the eager
    ones as it does without numba: the "before" arm of the step-time and bench tables."""
    global _COMPILED_OFF
    before, _COMPILED_OFF = _COMPILED_OFF, True
    try:
        yield
    finally:
        _COMPILED_OFF = before


@contextmanager
def forced_scan(impl: str) -> Iterator[None]:
    """Every scan left to the dispatcher (``impl="auto"``, the layers' default) inside the
    block runs ``impl``, a CPU scan, even on a GPU. The bench counts FLOPs under the loop: the
    chunked scan's cumulative sums are triangular matmuls whose size follows the chunk length
    that the trained weights allow (``chunk_size_for``), so counting them made a model's
    FLOPs move with its weights (KMM's read 0.068 then 0.063 GFLOP per second of motion)."""
    global _FORCED_SCAN
    if impl not in SCANS:
        raise ValueError(f"unknown scan {impl!r}; choose from {SCANS}")
    before, _FORCED_SCAN = _FORCED_SCAN, impl
    try:
        yield
    finally:
        _FORCED_SCAN = before


@contextmanager
def counted_state_updates() -> Iterator[list[int]]:
    """Counts the scans' state updates inside the block, in the yielded one-element list:
    B x L x D x N for every scan that runs, each update being at least one decay
    exp(delta_t A_n) and one multiply-add of the state h_t[d, n] (FreqSSM's shifted state
    matrix adds a softplus). The matrix-multiply FLOP counter does not see this work (in the
    compiled kernels it is element-wise loops), yet a Mamba layer's state of N per channel
    makes it N times its input's size; the bench times it at this machine's exp rate as the
    scans' part of a method's floor. Inside the block the fused kernels stand aside
    (``fusable``), so every scan passes ``selective_scan``, where it is counted. A block
    inside another counts its own updates, and the outer one counts them too."""
    global _STATE_UPDATES
    before, _STATE_UPDATES = _STATE_UPDATES, [0]
    mine = _STATE_UPDATES
    try:
        yield mine
    finally:
        _STATE_UPDATES = before
        if before is not None:
            before[0] += mine[0]


def selective_scan(u, delta, A, Bm, Cm, D=None, impl: str = "auto", a_shift=None):
    """Dispatching selective scan; see ``scan_sequential`` for shapes. ``a_shift`` (B, L, D):
    FreqSSM's per-step shift of a shared A (D, N), the state matrix of step t being
    ``stable_state_matrix(A, a_shift[:, t, :, None])``: the compiled scan builds it a step at
    a time; every other scan gets it as a (B, L, D, N) tensor."""
    if _STATE_UPDATES is not None:
        _STATE_UPDATES[0] += u.shape[0] * u.shape[1] * u.shape[2] * A.shape[-1]
    if impl == "auto" and _FORCED_SCAN is not None:
        impl = _FORCED_SCAN
    if impl == "auto":
        if u.is_cuda and A.dim() == 2 and a_shift is None and (fn := _cuda_scan()) is not None:
            # mamba-ssm wants channels first: u (B, D, L), B/C (B, G, N, L).
            y = fn(
                u.transpose(1, 2).contiguous(),
                delta.transpose(1, 2).contiguous(),
                A.contiguous(),
                Bm.permute(0, 2, 3, 1).contiguous(),
                Cm.permute(0, 2, 3, 1).contiguous(),
                D,
            )
            return y.transpose(1, 2)
        if u.is_cuda and _triton.supported(u, A, Bm):
            # without mamba-ssm: our fused kernel (one program per sample and channel block
            # walks the sequence with its states in registers; scan_triton.py)
            impl = "triton"
        elif u.is_cuda:
            # without triton: on a GPU the loop's L small steps are each a few kernel
            # launches, so the chunked scan's handful of whole-tensor ops wins at any size
            # (the (B, K, D, N) tensors that make it lose on a CPU are small for a GPU)
            impl = "chunked"
        elif not _COMPILED_OFF and _compiled.available() and u.dtype in (torch.float32, torch.float64):
            impl = "compiled"
        else:
            grad = torch.is_grad_enabled() and any(
                t is not None and t.requires_grad for t in (u, delta, A, Bm, Cm, a_shift)
            )
            impl = choose_scan(u.shape[1], u.shape[0] * u.shape[2] * A.shape[-1], grad)
    if impl not in _IMPLS:
        raise ValueError(f"unknown scan {impl!r}; choose from {SCANS}")
    if a_shift is not None:
        if impl == "compiled":
            return scan_compiled(u, delta, A, Bm, Cm, D, a_shift=a_shift)
        A = stable_state_matrix(A, a_shift.unsqueeze(-1))
    return _IMPLS[impl](u, delta, A, Bm, Cm, D)


def stable_state_matrix(A: torch.Tensor, shift: torch.Tensor, eps: float = STATE_EPS) -> torch.Tensor:
    """A_n = A + shift kept strictly negative: -(softplus(-(A + shift)) + eps).

    FTMoMamba's Eq. 9 adds frequency features to A; unconstrained, a positive sum would
    make exp(delta * A_n) > 1 and the state grow without bound. softplus(-a) ~ -a for a
    well below 0, so A_n ~ A + shift wherever the sum is clearly negative, and it bends
    smoothly towards -eps (never reaching 0) where it is not; eps keeps A_n < 0 even where
    float32 softplus underflows. Shapes broadcast: A (D, N), shift (B, L, D, 1) ->
    (B, L, D, N).

    Written as (-A) - shift and (-eps) - softplus: three passes over the (B, L, D, N) tensor
    instead of five (add, negate, softplus, add, negate), bit for bit the same (negation is
    exact and IEEE addition symmetric). FTMoMamba's training step at batch 64 went from 2.0
    to 1.8 s (one thread), at 256 from 8.5 to 8.3 s."""
    return torch.rsub(F.softplus(torch.neg(A) - shift), -eps)


@dataclass
class SSMConfig:
    """Mamba layer settings; defaults are the reference block's."""

    d_state: int = 16
    d_conv: int = 4
    expand: float = 2.0
    dt_rank: int | None = None  # ceil(d_model / 16) when None
    dt_min: float = 0.001
    dt_max: float = 0.1
    scan: str = "auto"

    def __post_init__(self) -> None:
        # a bad value set from the command line (train --set bsm_ssm.scan=...) fails here, not
        # at the first forward pass or, worse, as a silently tiny layer
        if self.scan not in ("auto", *SCANS):
            raise ValueError(f"scan must be one of {('auto', *SCANS)}, got {self.scan!r}")
        if self.d_state < 1 or self.d_conv < 1 or not self.expand > 0:
            raise ValueError(f"d_state and d_conv must be >= 1 and expand > 0, got {self}")
        if not 0 < self.dt_min < self.dt_max:
            raise ValueError(f"need 0 < dt_min < dt_max, got {self.dt_min} and {self.dt_max}")
        # the layers read `dt_rank or ceil(d / 16)`: 0 would build the default while the
        # checkpoint's config said 0
        if self.dt_rank is not None and self.dt_rank < 1:
            raise ValueError(f"dt_rank must be >= 1 (or None: from the width), got {self.dt_rank}")


class SelectiveSSM(nn.Module):
    """k isolated selective scans of one input.

    Scan i has its own depthwise causal Conv1D, x-projection to (delta, B, C), delta
    projection, A_i and D_i. ``directions[i]`` is +1 (scan t = 0..L-1) or -1 (scan the
    time-reversed input; the output is flipped back so every O_i is aligned with x).

    x: (B, L, E) -> O: (B, L, k, E)
    """

    def __init__(self, d_inner: int, directions: Sequence[int], cfg: SSMConfig, dt_rank: int) -> None:
        super().__init__()
        k = len(directions)
        self.k, self.d_inner, self.cfg = k, d_inner, cfg
        # which scans run reversed, as Python flags: a buffer asked (any/all) cost three
        # dispatched ops and a host read per call
        self._flip_any, self._flip_all = any(d < 0 for d in directions), all(d < 0 for d in directions)
        self._reversed = tuple(d < 0 for d in directions)
        n = cfg.d_state
        self.conv_weight = nn.Parameter(torch.empty(k * d_inner, 1, cfg.d_conv))
        self.conv_bias = nn.Parameter(torch.zeros(k * d_inner))
        nn.init.kaiming_uniform_(self.conv_weight, a=math.sqrt(5))
        self.x_proj = nn.Parameter(torch.randn(k, d_inner, dt_rank + 2 * n) / math.sqrt(d_inner))
        self.dt_proj = nn.Parameter(torch.empty(k, dt_rank, d_inner).uniform_(-1, 1) * dt_rank**-0.5)
        # delta starts log-uniform in [dt_min, dt_max]: softplus^{-1} of those values as bias
        dt = torch.exp(torch.rand(k, d_inner) * (math.log(cfg.dt_max) - math.log(cfg.dt_min)) + math.log(cfg.dt_min))
        self.dt_bias = nn.Parameter(dt + torch.log(-torch.expm1(-dt)))
        # S4D-real initialisation A = -(1..N); A = -exp(A_log) keeps every A_i negative (stable)
        self.A_log = nn.Parameter(torch.log(torch.arange(1, n + 1, dtype=torch.float32)).repeat(k * d_inner, 1))
        self.D = nn.Parameter(torch.ones(k * d_inner))
        self.dt_rank = dt_rank

    def _causal_conv(self, x: torch.Tensor) -> torch.Tensor:
        """Depthwise causal Conv1D over time, channels last: (B, L, C) -> (B, L, C). Compiled on
        the CPU (``causal_conv``: one pass each way, where K shifted multiply-adds made 2K
        and their backward materialised every shifted slice)."""
        # (K, C): tap K-1 multiplies the current step
        return causal_conv(x, self.conv_weight[:, 0].t(), self.conv_bias)

    def _flip(self, x: torch.Tensor) -> torch.Tensor:
        """Reverse time on the scans marked -1; x: (B, L, k, ...). With both directions
        (BSM), only the reversed scans' slices are flipped and stacked with the others: a
        ``where`` over the whole tensor read a flipped copy of every slice as well."""
        if not self._flip_any:
            return x
        if self._flip_all:
            return x.flip(1)
        return torch.stack([x[:, :, i].flip(1) if r else x[:, :, i] for i, r in enumerate(self._reversed)], dim=2)

    def _spread(self, x: torch.Tensor) -> torch.Tensor:
        """One input per scan, reversed for the scans marked -1: (B, L, E) -> (B, L, k, E),
        the reversed copy made once however many scans read it."""
        bsz, L, e = x.shape
        if not self._flip_any:
            return x.unsqueeze(2).expand(bsz, L, self.k, e)
        xf = x.flip(1)
        if self._flip_all:
            return xf.unsqueeze(2).expand(bsz, L, self.k, e)
        return torch.stack([xf if r else x for r in self._reversed], dim=2)

    def forward(
        self, x: torch.Tensor, a_shift: torch.Tensor | None = None, c_shift: torch.Tensor | None = None
    ) -> torch.Tensor:
        """x: (B, L, E). Optional FTMoMamba hooks: ``a_shift`` (B, L, E), added to the state
        matrix of every scan at each step (FreqSSM, see ``stable_state_matrix``), and
        ``c_shift`` (B, N), added to every step's output matrix C (TextSSM). Both are given
        in x's time order; the reversed scans see them reversed like x."""
        bsz, L, e = x.shape
        k, n = self.k, self.cfg.d_state
        xs = self._spread(x).reshape(bsz, L, k * e)
        xc = F.silu(self._causal_conv(xs)).view(bsz, L, k, e)
        proj = torch.einsum("blke,kef->blkf", xc, self.x_proj)
        dt, Bm, Cm = proj.split([self.dt_rank, n, n], dim=-1)
        delta = F.softplus(torch.einsum("blkr,kre->blke", dt, self.dt_proj) + self.dt_bias)
        A = -torch.exp(self.A_log)
        shift = self._spread(a_shift).reshape(bsz, L, k * e) if a_shift is not None else None
        if c_shift is not None:
            Cm = Cm + c_shift[:, None, None, :]
        y = selective_scan(
            xc.reshape(bsz, L, k * e), delta.reshape(bsz, L, k * e), A, Bm, Cm, self.D, self.cfg.scan, shift
        )
        return self._flip(y.view(bsz, L, k, e))

    def fusable(self, *tensors: torch.Tensor | None) -> bool:
        """Whether ``mixed`` (and ``MambaBlock``) can run the fused inference kernel on these
        inputs (``ssm_fused``): on the CPU in float32 with nothing to differentiate, with the
        scan left to the dispatcher and not inside ``eager_scans``, ``forced_scan`` or
        ``counted_state_updates``."""
        if self.cfg.scan != "auto" or _COMPILED_OFF or _FORCED_SCAN is not None or _STATE_UPDATES is not None:
            return False
        return _fused_applies(self, *tensors)

    def mixed(
        self,
        x: torch.Tensor,
        mix: torch.Tensor | None = None,
        a_shift: torch.Tensor | None = None,
        c_shift: torch.Tensor | None = None,
    ) -> torch.Tensor:
        """sum_i mix_i O_i over the k scans (a plain sum where ``mix`` (k, E) is None):
        x (B, L, E) -> (B, L, E); hooks as ``forward``. One compiled call where ``fusable``,
        else ``forward``'s outputs mixed."""
        if self.fusable(x, mix, a_shift, c_shift):
            return fused_ssm(self, x, mix=mix, a_shift=a_shift, c_shift=c_shift)
        o = self(x, a_shift, c_shift)
        return o.sum(2) if mix is None else (o * mix).sum(2)


class MambaBlock(nn.Module):
    """Gu & Dao's Mamba block with k isolated scans aggregated by a learned linear mix.

    in-projection to x and gate z -> ``SelectiveSSM`` (k scans) -> Aggregate -> * SiLU(z)
    -> out-projection. Aggregate is sum_i w_i O_i with one learned weight per scan and
    channel (initialised 1/k): the paper leaves Aggregate unspecified; a per-channel
    linear mix keeps HTM's parameter count close to one scan's while letting the layer
    weigh its scans. With directions (+1, -1) this is the bidirectional gate-and-sum.

    x: (B, L, d_model) -> (B, L, d_model)
    """

    def __init__(self, d_model: int, directions: Sequence[int] = (1,), cfg: SSMConfig | None = None) -> None:
        super().__init__()
        cfg = cfg or SSMConfig()
        self.d_inner = max(1, round(cfg.expand * d_model))
        dt_rank = cfg.dt_rank or math.ceil(d_model / 16)
        self.in_proj = nn.Linear(d_model, 2 * self.d_inner)
        self.ssm = SelectiveSSM(self.d_inner, directions, cfg, dt_rank)
        k = len(directions)
        self.mix = nn.Parameter(torch.full((k, self.d_inner), 1.0 / k))
        self.out_proj = nn.Linear(self.d_inner, d_model)

    @property
    def n_scans(self) -> int:
        return self.ssm.k

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        xz = self.in_proj(x)
        if self.ssm.fusable(xz, self.mix):
            # the SSM, the mix and the gate in one compiled call (ssm_fused)
            e = self.d_inner
            return self.out_proj(fused_ssm(self.ssm, xz, (0, e), self.mix, gate_from=e))
        xi, z = xz.chunk(2, dim=-1)
        o = self.ssm(xi)  # (B, L, k, E)
        y = (o * self.mix).sum(2)
        return self.out_proj(y * F.silu(z))


def bidirectional(d_model: int, cfg: SSMConfig | None = None) -> MambaBlock:
    """Forward + time-reversed scan, gated and summed (BSM, KMM)."""
    return MambaBlock(d_model, (1, -1), cfg)


class ResidualMamba(nn.Module):
    """Pre-norm residual wrapper: x + Mamba(LayerNorm(x)). x: (B, L, d) -> (B, L, d)."""

    def __init__(self, d_model: int, directions: Sequence[int] = (1,), cfg: SSMConfig | None = None) -> None:
        super().__init__()
        self.norm = nn.LayerNorm(d_model)
        self.mamba = MambaBlock(d_model, directions, cfg)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return x + self.mamba(self.norm(x))

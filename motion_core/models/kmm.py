"""KMM's generator (Zhang et al. 2024): a masked bidirectional Mamba over residual-VQ tokens.

Input per token i of a timeline: the sum of its 6 code embeddings when known, a learned
[MASK] embedding when not, plus the projection of its own segment's sentence embedding;
one text token (the mean of the segment projections) is concatenated in front, as the
paper's "text embedding concatenated with motion tokens". 4 pre-norm residual
bidirectional Mamba layers (forward + time-reversed scan, gated and summed). Heads: the
base layer's codes from the hidden state h_i; residual layer q from h_i plus the embeddings
of the layers below it (teacher-forced in training), so the residual codes follow the base
code actually drawn.

Departure from the paper, and why: the text projection is added to every token of its
segment as well. A long span's tokens sit far from any prefix token, and the scan's state
decays; the per-token term is how each segment's text conditions its own span within one
sequence, which is what in-filling timeline boundaries needs.

Second departure (``word_pool``, off by default; a checkpoint's config says whether it was
trained with it): the segment vector also gets a learned attention pooling (``word_heads``
queries) of the frozen encoder's token embeddings. Mean-pooled MiniLM sentences barely
separate the words our prompts turn on ("punches with the left arm three times" vs "right
arm": cosine 0.989), and the side and count words are where the generator failed most.

Training (``loss``): a mask ratio r ~ cos(pi/2 u) (MoMask's schedule); with key-frame
masking the highest-gamma 30% of tokens (``keyframes.density_peaks`` on the tokeniser's
latents) are masked first, then random others up to r (below 30%, a random subset of the
key frames); ``mask="random"`` is the ablation. Cross-entropy on the masked tokens, all 6
layers. Alignment (Eq. 12-14): T = normalised projection of the (learned) text encoding,
M = normalised projection of the mean of a segment's true token embeddings, sim = T M^T /
tau with learnable tau, L = lambda (CE(sim, y) + CE(sim^T, y)), lambda 0.5. Departure: our
corpus repeats captions, so every pair with the same caption counts as a positive (the
targets are spread over them) instead of y = [0..b-1] marking the repeats negative.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
import torch
import torch.nn.functional as F
from torch import nn

from ..nn.ssm import ResidualMamba, SSMConfig


@dataclass
class KMMConfig:
    codebook_size: int = 512
    quantizers: int = 6
    d_model: int = 128  # sized for 10 decoding passes of a 10 s timeline in ~0.1 s on 2 CPU cores
    layers: int = 4
    text_dim: int = 384
    ssm: SSMConfig = None  # type: ignore[assignment]
    keyframe_ratio: float = 0.3
    mask: str = "keyframe"  # or "random" (ablation)
    align: bool = True
    align_weight: float = 0.5  # lambda of Eq. 14
    cond_drop: float = 0.1
    # word pooling (our addition, see the module docstring): learned attention pooling of the
    # frozen encoder's token embeddings, added to each segment's sentence projection
    word_pool: bool = False
    word_heads: int = 4
    # segment phase (our addition, see the module docstring)
    phase: bool = False
    phase_freqs: int = 12

    def __post_init__(self) -> None:
        if self.ssm is None:
            self.ssm = SSMConfig(expand=1.0, d_state=8)
        elif isinstance(self.ssm, dict):
            self.ssm = SSMConfig(**self.ssm)
        if self.mask not in ("keyframe", "random"):
            raise ValueError(f"mask must be 'keyframe' or 'random', got {self.mask!r}")

    def to_dict(self) -> dict:
        return asdict(self)


def segment_phase(seg_ids: torch.Tensor, valid: torch.Tensor, freqs: int) -> torch.Tensor:
    """Each token's place in its segment: seg_ids (B, n) long (a segment's tokens contiguous
    within a row), valid (B, n) bool -> (B, n, 2 freqs + 1): sin and cos of pi k p (k = 1..freqs,
    p = (position in segment + 1/2) / segment length) and log(length) / log(64); zero where
    not valid."""
    oh = F.one_hot(seg_ids.clamp(min=0), int(seg_ids.max()) + 1).float() * valid[..., None].float()  # (B, n, S)
    length = (oh.sum(1, keepdim=True) * oh).sum(-1).clamp(min=1)  # (B, n)
    pos = ((oh.cumsum(1) - 1) * oh).sum(-1)
    ang = ((pos + 0.5) / length)[..., None] * (torch.arange(1, freqs + 1, device=seg_ids.device) * math.pi)
    feats = torch.cat([ang.sin(), ang.cos(), (length.log() / math.log(64))[..., None]], -1)
    return feats * valid[..., None].float()


class KMMGenerator(nn.Module):
    def __init__(self, cfg: KMMConfig | None = None) -> None:
        super().__init__()
        self.cfg = cfg = cfg or KMMConfig()
        d, k = cfg.d_model, cfg.codebook_size
        self.code_emb = nn.ModuleList(nn.Embedding(k, d) for _ in range(cfg.quantizers))
        self.mask_emb = nn.Parameter(torch.randn(d) * 0.02)
        self.pad_emb = nn.Parameter(torch.randn(d) * 0.02)
        self.text_proj = nn.Sequential(nn.Linear(cfg.text_dim, d), nn.GELU(), nn.Linear(d, d))
        self.layers = nn.ModuleList(ResidualMamba(d, (1, -1), cfg.ssm) for _ in range(cfg.layers))
        self.norm = nn.LayerNorm(d)
        self.heads = nn.ModuleList(nn.Linear(d, k) for _ in range(cfg.quantizers))
        # alignment heads and tau (as log(1/tau), CLIP's parametrisation, init tau = 0.07)
        self.align_text = nn.Linear(d, d)
        self.align_motion = nn.Linear(d, d)
        self.logit_scale = nn.Parameter(torch.tensor(math.log(1 / 0.07)))
        if cfg.word_pool:
            self.word_norm = nn.LayerNorm(cfg.text_dim)
            self.word_query = nn.Parameter(torch.randn(cfg.word_heads, cfg.text_dim) * 0.02)
            self.word_out = nn.Sequential(nn.Linear(cfg.word_heads * cfg.text_dim, d), nn.GELU(), nn.Linear(d, d))
            # zero output: a generator trained without words behaves exactly as before at the
            # start of fine-tuning with them
            nn.init.zeros_(self.word_out[-1].weight)
            nn.init.zeros_(self.word_out[-1].bias)
        if cfg.phase:
            # zero: a generator trained without phase behaves exactly as before at the start
            self.phase_proj = nn.Linear(2 * cfg.phase_freqs + 1, d)
            nn.init.zeros_(self.phase_proj.weight)
            nn.init.zeros_(self.phase_proj.bias)

    def text_vectors(
        self, sentence: torch.Tensor, words: torch.Tensor | None = None, word_mask: torch.Tensor | None = None
    ) -> torch.Tensor:
        """Per-segment conditioning vectors (S, d): sentence (S, text_dim) embeddings, and with
        ``word_pool`` the segments' token embeddings words (S, L, text_dim) and word_mask (S, L)."""
        v = self.text_proj(sentence)
        if not self.cfg.word_pool:
            return v
        if words is None or word_mask is None:
            raise ValueError("this generator pools words: pass the token embeddings and their mask")
        w = self.word_norm(words)  # (S, L, td)
        score = torch.einsum("sld,hd->shl", w, self.word_query) / math.sqrt(w.shape[-1])
        score = score.masked_fill(~word_mask[:, None], float("-inf"))
        pooled = torch.einsum("shl,sld->shd", score.softmax(-1), w)  # (S, H, td)
        return v + self.word_out(pooled.flatten(1))

    # -- shared forward ---------------------------------------------------------------
    def embed_codes(self, codes: torch.Tensor) -> torch.Tensor:
        """codes (B, n, Q) -> summed embeddings (B, n, d)."""
        return sum(emb(codes[..., q]) for q, emb in enumerate(self.code_emb))

    def hidden(
        self,
        codes: torch.Tensor,
        masked: torch.Tensor,
        valid: torch.Tensor,
        seg_text: torch.Tensor,
        seg_ids: torch.Tensor | None = None,
    ) -> torch.Tensor:
        """codes (B, n, Q) (ignored where masked), masked / valid (B, n) bool, seg_text (B, n, d)
        the per-token projected text, seg_ids (B, n) (needed with ``phase``) -> hidden states
        of the motion tokens (B, n, d)."""
        x = self.embed_codes(codes.clamp(min=0))
        x = torch.where(masked[..., None], self.mask_emb, x)
        if self.cfg.phase:
            if seg_ids is None:
                raise ValueError("this generator reads segment phase: pass seg_ids")
            x = x + self.phase_proj(segment_phase(seg_ids, valid, self.cfg.phase_freqs))
        x = torch.where(valid[..., None], x + seg_text, self.pad_emb)
        w = valid.float()[..., None]
        prefix = (seg_text * w).sum(1, keepdim=True) / w.sum(1, keepdim=True).clamp(min=1)
        h = torch.cat([prefix, x], dim=1)
        for layer in self.layers:
            h = layer(h)
        return self.norm(h[:, 1:])

    def logits(self, h: torch.Tensor, codes: torch.Tensor, layer: int) -> torch.Tensor:
        """Layer ``layer``'s code logits (B, n, K) given h and the codes of the layers below."""
        if layer == 0:
            return self.heads[0](h)
        below = sum(self.code_emb[q](codes[..., q].clamp(min=0)) for q in range(layer))
        return self.heads[layer](h + below)

    # -- training -----------------------------------------------------------------------
    def training_mask(self, is_key: torch.Tensor, valid: torch.Tensor, generator: torch.Generator) -> torch.Tensor:
        """Which tokens to mask (B, n) bool. is_key (B, n): the token is among the top
        ``keyframe_ratio`` of its clip by gamma."""
        b, n = valid.shape
        lengths = valid.sum(1)
        r = torch.cos(math.pi / 2 * torch.rand(b, generator=generator))
        m = torch.clamp((r * lengths).ceil().long(), min=1)
        noise = torch.rand(b, n, generator=generator)
        if self.cfg.mask == "keyframe":
            # key frames sort before the rest (score < 1), random order within each group
            score = torch.where(is_key, noise, 1.0 + noise)
        else:
            score = noise
        score = torch.where(valid, score, torch.full_like(score, 9.0))
        order = score.argsort(1)
        pos = torch.empty_like(order)
        pos.scatter_(1, order, torch.arange(n).expand(b, n).contiguous())
        return (pos < m[:, None]) & valid

    def loss(
        self,
        codes: torch.Tensor,
        is_key: torch.Tensor,
        valid: torch.Tensor,
        seg_ids: torch.Tensor,
        seg_text: torch.Tensor,
        seg_drop: torch.Tensor,
        same_text: torch.Tensor,
        generator: torch.Generator,
        seg_words: torch.Tensor | None = None,
        seg_word_mask: torch.Tensor | None = None,
    ) -> dict[str, torch.Tensor]:
        """codes (B, n, Q), is_key (B, n) (see ``training_mask``), valid (B, n), seg_ids (B, n) long in [0, S),
        seg_text (S, text_dim) sentence embeddings of all segments in the batch, seg_drop (S,)
        bool (segment trained on the empty text), same_text (S, S) bool (equal captions);
        seg_words (S, L, text_dim) / seg_word_mask (S, L): the segments' token embeddings
        (the empty text's where dropped), with ``word_pool``."""
        masked = self.training_mask(is_key, valid, generator)
        proj = self.text_vectors(seg_text, seg_words, seg_word_mask)  # (S, d)
        h = self.hidden(codes, masked, valid, proj[seg_ids], seg_ids)
        ce = []
        for q in range(self.cfg.quantizers):
            lg = self.logits(h[masked], codes[masked], q)
            ce.append(F.cross_entropy(lg, codes[masked][:, q]))
        rec = torch.stack(ce)
        out = {"ce": rec.sum(), "ce_base": rec[0]}
        with torch.no_grad():
            out["acc_base"] = (self.heads[0](h[masked]).argmax(-1) == codes[masked][:, 0]).float().mean()
        loss = out["ce"]
        if self.cfg.align:
            keep = ~seg_drop
            if int(keep.sum()) > 1:
                tok = self.embed_codes(codes.clamp(min=0))
                S = len(seg_text)
                onehot = F.one_hot(seg_ids, S).float() * valid[..., None].float()  # (B, n, S)
                pooled = torch.einsum("bns,bnd->sd", onehot, tok) / onehot.sum((0, 1))[:, None].clamp(min=1)
                T = F.normalize(self.align_text(proj[keep]), dim=-1)
                M = F.normalize(self.align_motion(pooled[keep]), dim=-1)
                sim = T @ M.t() * self.logit_scale.clamp(max=math.log(100)).exp()
                target = same_text[keep][:, keep].float()
                target = target / target.sum(1, keepdim=True)
                align = F.cross_entropy(sim, target) + F.cross_entropy(sim.t(), target)
                out["align"] = align
                loss = loss + self.cfg.align_weight * align
        out["loss"] = loss
        return out

    # -- generation ---------------------------------------------------------------------
    @torch.no_grad()
    def generate(
        self,
        seg_text: torch.Tensor,
        empty_text: torch.Tensor,
        seg_tokens: list[int],
        generator: torch.Generator,
        iterations: int = 10,
        guidance: float = 4.0,
        temperature: float = 1.0,
        top_k: float = 0.9,
        infill: int = 2,
        infill_iterations: int = 4,
        words: tuple[torch.Tensor, torch.Tensor] | None = None,
    ) -> torch.Tensor:
        """One timeline's codes (n, Q).

        seg_text (S, text_dim) and empty_text (text_dim,) sentence embeddings; seg_tokens:
        tokens per segment. Iterative masked decoding from all-masked (cosine schedule;
        after each pass the least confident base codes drawn so far are masked again),
        classifier-free guidance on the base layer, residual layers drawn greedily for each
        token as it is fixed. Then the ``infill`` tokens on each side of every segment
        boundary are masked again and in-filled in ``infill_iterations`` passes, now seeing
        both neighbouring segments decoded. ``words``: with ``word_pool``, token embeddings
        (S + 1, L, text_dim) and mask (S + 1, L) of the segments' texts and, last, the empty text.
        """
        n = int(sum(seg_tokens))
        dev = seg_text.device
        seg_ids = torch.repeat_interleave(torch.arange(len(seg_tokens)), torch.tensor(seg_tokens))[None].to(dev)
        proj = self.text_vectors(torch.cat([seg_text, empty_text[None]]), *(words or (None, None)))
        cond = proj[seg_ids]  # (1, n, d)
        uncond = proj[-1].expand(1, n, -1)
        valid = torch.ones(1, n, dtype=torch.bool, device=dev)
        codes = torch.zeros(1, n, self.cfg.quantizers, dtype=torch.long, device=dev)
        masked = torch.ones(1, n, dtype=torch.bool, device=dev)
        self._decode(codes, masked, valid, cond, uncond, seg_ids, generator, iterations, guidance, temperature, top_k)
        if infill > 0 and len(seg_tokens) > 1:
            bounds = np.cumsum(seg_tokens)[:-1]
            masked = torch.zeros(1, n, dtype=torch.bool, device=dev)
            for b in bounds:
                masked[0, max(0, b - infill) : min(n, b + infill)] = True
            self._decode(
                codes, masked, valid, cond, uncond, seg_ids, generator, infill_iterations, guidance, temperature, top_k
            )
        return codes[0]

    @torch.no_grad()
    def generate_batch(
        self,
        texts: torch.Tensor,
        empty_text: torch.Tensor,
        n: int,
        generator: torch.Generator,
        iterations: int = 10,
        guidance: float = 4.0,
        temperature: float = 1.0,
        top_k: float = 0.9,
        words: tuple[torch.Tensor, torch.Tensor] | None = None,
    ) -> torch.Tensor:
        """B single-segment sequences of ``n`` tokens decoded together: texts (B, text_dim),
        empty_text (text_dim,) -> codes (B, n, Q). Row 0 of a batch of one equals
        ``generate(texts, empty_text, [n], generator)`` with the same generator state; in a
        larger batch the rows share the generator's stream, so a row depends on its batch.
        ``words`` as in ``generate`` (B + 1 rows, the empty text last)."""
        b = texts.shape[0]
        proj = self.text_vectors(torch.cat([texts, empty_text[None]]), *(words or (None, None)))
        cond = proj[:-1, None].expand(b, n, -1)
        uncond = proj[-1].expand(b, n, -1)
        dev = texts.device
        valid = torch.ones(b, n, dtype=torch.bool, device=dev)
        codes = torch.zeros(b, n, self.cfg.quantizers, dtype=torch.long, device=dev)
        masked = torch.ones(b, n, dtype=torch.bool, device=dev)
        seg_ids = torch.zeros(b, n, dtype=torch.long, device=dev)
        self._decode(codes, masked, valid, cond, uncond, seg_ids, generator, iterations, guidance, temperature, top_k)
        return codes

    def _decode(
        self, codes, masked, valid, cond, uncond, seg_ids, generator, iterations, guidance, temperature, top_k
    ) -> None:
        """Fill ``codes`` (B, n, Q) where ``masked`` (B, n) (in place) by iterative confidence
        re-masking, every row on the same schedule (rows must hold equally many masked tokens)."""
        b = codes.shape[0]
        total = int(masked.sum(1).max())
        for it in range(iterations):
            if not bool(masked.any()):
                break
            if guidance == 1.0:  # plain conditional sampling: the unconditional pass would cancel out
                h = self.hidden(codes, masked, valid, cond, seg_ids)
                lg = self.logits(h, codes, 0)
            else:
                both = torch.cat([codes, codes])
                two = (torch.cat([x, x]) for x in (masked, valid))
                h = self.hidden(both, *two, torch.cat([cond, uncond]), torch.cat([seg_ids, seg_ids]))
                lg_c, lg_u = self.logits(h, both, 0).chunk(2)
                lg = lg_u + guidance * (lg_c - lg_u)
            lg = lg / max(temperature, 1e-4)
            if top_k < 1.0:  # keep the top (1 - top_k) share of codes, MoMask's "top-k 0.9"
                kth = max(1, round((1 - top_k) * lg.shape[-1]))
                thresh = lg.topk(kth, dim=-1).values[..., -1:]
                lg = lg.masked_fill(lg < thresh, float("-inf"))
            probs = lg.softmax(-1)
            draw = torch.multinomial(probs.flatten(0, 1), 1, generator=generator)[:, 0].view(b, -1)
            conf = probs.gather(-1, draw[..., None])[..., 0]
            new = masked.clone()
            codes[..., 0] = torch.where(new, draw, codes[..., 0])
            h_c = h[:b]
            for q in range(1, self.cfg.quantizers):
                pick = self.logits(h_c, codes, q).argmax(-1)
                codes[..., q] = torch.where(new, pick, codes[..., q])
            conf = torch.where(new, conf, torch.full_like(conf, float("inf")))  # fixed tokens stay fixed
            # tokens still to be masked after this pass: cosine schedule over the masked set
            keep_masked = math.floor(total * math.cos(math.pi / 2 * (it + 1) / iterations))
            masked = torch.zeros_like(masked)
            if keep_masked > 0:
                masked.scatter_(1, conf.argsort(1)[:, :keep_masked], True)

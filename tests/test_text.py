import socket

import pytest
import torch

from motion_core.nn.text import TextEncoder


def test_paraphrases_closer_than_unrelated(text_encoder):
    e = text_encoder.encode(["a person walks forward", "someone is walking ahead", "a man plays the violin on a stage"])
    assert e.shape == (3, 384)
    assert torch.allclose(e.norm(dim=-1), torch.ones(3), atol=1e-5)
    para, unrelated = float(e[0] @ e[1]), float(e[0] @ e[2])
    assert para > unrelated + 0.3, (para, unrelated)


def test_batching_and_cache_are_consistent(text_encoder):
    texts = ["a person jumps up", "a person kicks with the left leg", "a person jumps up"]
    batched = text_encoder.encode(texts)
    single = text_encoder.backend.encode_batch(["a person kicks with the left leg"]).sentence[0]
    assert torch.allclose(batched[1], single, atol=1e-5)
    assert torch.equal(batched[0], batched[2])
    tok = text_encoder.encode_tokens(["a person jumps up"])
    assert tok.tokens.shape[-1] == 384 and tok.mask.dtype == torch.bool


def test_loads_without_network(monkeypatch):
    """Loading and encoding must not open a single socket."""

    def refuse(*args, **kwargs):
        raise AssertionError(f"network access attempted: {args}")

    monkeypatch.setattr(socket.socket, "connect", refuse)
    monkeypatch.setattr(socket, "create_connection", refuse)
    enc = TextEncoder()
    assert enc.encode("a person walks forward").shape == (1, 384)


def test_unknown_backend():
    with pytest.raises(ValueError, match="unknown text encoder"):
        TextEncoder("clip-not-installed")


def test_word_embeddings_are_cached_padded_and_match_the_encoders_tokens(text_encoder):
    texts = ["a person punches with the left arm three times", "a person jumps", ""]
    tokens, mask = text_encoder.encode_words(texts)
    assert tokens.shape[:2] == mask.shape and tokens.shape[-1] == 384
    lengths = mask.sum(1).tolist()
    assert lengths[0] > lengths[1] > lengths[2] >= 2  # [CLS] ... [SEP]; the empty text is the two
    alone = text_encoder.encode_tokens([texts[1]])
    assert torch.allclose(tokens[1, : lengths[1]], alone.tokens[0][alone.mask[0]], atol=1e-4)
    assert torch.all(tokens[~mask] == 0)
    again, _ = text_encoder.encode_words([texts[1]])  # from the cache, padded to its own length
    assert torch.equal(again[0], tokens[1, : lengths[1]])

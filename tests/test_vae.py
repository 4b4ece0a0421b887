"""The motion VAE's encoder and decoder do not depend on the padding of their batch."""

from __future__ import annotations

import torch

from motion_core.models.vae import MotionVAE, VAEConfig


def test_a_clip_encodes_and_decodes_the_same_alone_and_in_a_padded_batch():
    """A 22-frame clip batched with a 48-frame one: its posterior and its decoded frames
    equal those of the clip alone. Before the fix, the input projection's and the first
    convolution's biases turned the padding into nonzero frames that the strided
    convolutions blended into the clip's last tokens (cached training latents moved by
    up to 10% with their batch's composition)."""
    torch.manual_seed(0)
    vae = MotionVAE().eval()
    x = torch.randn(2, 48, 263)
    mask = torch.ones(2, 48, dtype=torch.bool)
    mask[1, 22:] = False
    with torch.no_grad():
        mu, logvar = vae.encode(x, mask)
        mu1, logvar1 = vae.encode(x[1:, :24], mask[1:, :24])
        assert torch.allclose(mu[1], mu1[0], atol=1e-5) and torch.allclose(logvar[1], logvar1[0], atol=1e-5)
        z = torch.randn(2, 2, 256)
        both = vae.decode(z, torch.tensor([48, 22]))
        alone = vae.decode(z[1:], 22)
        assert torch.allclose(both[1, :22], alone[0, :22], atol=1e-5)


def test_a_narrow_latent_has_its_own_width_and_decodes_from_it() -> None:
    """MotionLCM-V2's 16 x 32 latent: the transformers stay 256 wide, the latent is 32."""
    torch.manual_seed(0)
    vae = MotionVAE(VAEConfig(latent_tokens=16, z_width=32, layers=1, ff=64)).eval()
    assert vae.latent_shape == (16, 32)
    x = torch.randn(2, 40, vae.cfg.feature_dim)
    mask = torch.ones(2, 40, dtype=torch.bool)
    mu, logvar = vae.encode(x, mask)
    assert mu.shape == logvar.shape == (2, 16, 32)
    assert vae.decode(mu, 40).shape == (2, 40, vae.cfg.feature_dim)


def test_the_temporal_vae_is_padding_invariant_and_pads_its_latent_with_zeros() -> None:
    from motion_core.models.conv_vae import ConvMotionVAE, ConvVAEConfig

    torch.manual_seed(0)
    vae = ConvMotionVAE(ConvVAEConfig(z_width=8)).eval()
    assert vae.latent_shape == (56, 8) and vae.frames_per_token == 4
    x = torch.randn(2, 120, 263)
    mask = torch.ones(2, 120, dtype=torch.bool)
    mask[1, 90:] = False  # clip 1 is 90 frames: 23 tokens
    with torch.no_grad():
        mu, logvar = vae.encode(x, mask)
        alone, _ = vae.encode(x[1:, :92], mask[1:, :92])
        assert torch.allclose(alone, mu[1:], atol=1e-5)
        assert mu[1, 23:].abs().max() == 0 and mu[0, 30:].abs().max() == 0 and mu[1, 22].abs().max() > 0
        assert (logvar[1, 23:] < -20).all()  # sampling a padded token gives its mean, 0
        batch = vae.decode(mu, mask.sum(1), t_pad=120)
        one = vae.decode(mu[1:], torch.tensor([90]))
        assert batch.shape == (2, 120, 263) and one.shape == (1, 92, 263)
        assert torch.allclose(one[:, :90], batch[1:, :90], atol=1e-5)


def test_the_temporal_vae_takes_the_shipped_tokenisers_convolutions() -> None:
    from motion_core.inference import checkpoints
    from motion_core.models.conv_vae import ConvMotionVAE

    vae = ConvMotionVAE()
    rvq = checkpoints.read(checkpoints.WEIGHTS / "kmm.pt")["rvq"]
    assert vae.init_from_tokeniser(checkpoints.float32_state(rvq)) > 40
    sd = vae.state_dict()
    assert torch.equal(sd["encoder.0.weight"], rvq["encoder.0.weight"].float())
    assert torch.equal(sd["decoder.3.conv1.weight"], rvq["decoder.3.conv1.weight"].float())

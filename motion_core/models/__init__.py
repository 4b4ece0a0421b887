"""Generators and their parts: motion VAE, denoisers, masked Mamba."""

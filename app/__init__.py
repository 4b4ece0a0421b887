"""Gradio front end of Motion Mamba Studio (the only package that imports Gradio)."""

"""Evaluation of tracker output against registered ground truth."""

"""Screens and modals of the poppy TUI."""

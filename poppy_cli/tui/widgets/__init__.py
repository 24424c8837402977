"""Widgets of the poppy TUI, one module per area."""

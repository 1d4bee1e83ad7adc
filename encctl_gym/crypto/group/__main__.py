"""``python -m encctl_gym.crypto.group``: regenerate the shipped-group file."""

from .generation import write_shipped_groups

write_shipped_groups()

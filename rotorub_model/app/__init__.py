"""What a user runs: the paper's studies, the main job (reproduce), its report, and the CLI."""

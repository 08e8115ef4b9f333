"""The games: snowman (build snowmen that come alive) and tasbada (a multi-reality quest)."""

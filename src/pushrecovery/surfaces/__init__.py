"""Decision surfaces: which states each balance strategy can recover (pure, vectorised)."""

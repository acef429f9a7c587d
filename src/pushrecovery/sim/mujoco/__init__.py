"""MuJoCo physics backend: models generated from the parameters, behind the Plant protocol."""

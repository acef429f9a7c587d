"""Many pushes in one compiled loop each: the ankle PD pendulum, Sec. IV's stepping model."""

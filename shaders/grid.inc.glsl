// Compute-only: the linear index of an invocation in a 2D grid of 1D workgroups (groupsX groups per
// row; a 1D grid may not exceed 65535 groups on every device).
uint linearInvocation(uint groupsX, uint groupSize) {
  return (gl_WorkGroupID.y * groupsX + gl_WorkGroupID.x) * groupSize + gl_LocalInvocationIndex;
}

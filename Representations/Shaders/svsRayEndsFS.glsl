// Per-frame ray ends (one pass, so the slices need not recompute them): r = the
// distance at which the view ray stops (opaque geometry, ground, or the top of the
// atmosphere), g = the distance to the ground (infinity when it misses), ba = the
// air's optical lengths from the eye to where the ray enters the cloud box
// (BoxEntryOpticalLengths).
in vec2 texCoord;
uniform int steps; // the march's samples per segment (svsMarchFS.glsl)

void main()
{
  vec3 origin, direction;
  ViewRay(texCoord, origin, direction);
  float tGround;
  float tEnd = RayEnd(texCoord, origin, direction, tGround);
  gl_FragData[0] = vec4(tEnd, tGround, BoxEntryOpticalLengths(origin, direction, tEnd, steps));
}

// Billboard splatting of metaball clouds (002 §3.3), the sun's pass
// (vtkNimbusCloudSplatMapper): one square per metaball facing the sun (parallel
// projection along the sunlight), drawn instanced, four corners per instance
// (a triangle strip; the corner from gl_VertexID).
//VTK::System::Dec
in vec4 ball;        // xyz: the centre (world), w: the radius R (world units)
in vec2 ballOptics;  // x: kappa = k d R (the ball's optical scale: tau = kappa C), y: unused
uniform vec3 sunAxisX;   // the sun frame (CloudSplats.h SplatFrame): two axes across the light
uniform vec3 sunAxisY;
uniform vec3 toSun;      // and the unit vector toward the sun
uniform vec4 sunRect;    // (x min, y min, 1 / width, 1 / height) of the frame's window
uniform float planeDepth; // the layer's plane: depth -dot(x, toSun) (world units)
uniform float slabThickness; // from the previous layer's plane to this one (world units)
out vec2 corner;     // the corner of the square, in units of R
out float kappa;
out vec2 planeOffsets; // (this plane's and the previous plane's depth - centre depth) / R

void main()
{
  corner = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1)) * 2.0 - 1.0;
  vec3 p = ball.xyz + (sunAxisX * corner.x + sunAxisY * corner.y) * ball.w;
  vec2 window = (vec2(dot(p, sunAxisX), dot(p, sunAxisY)) - sunRect.xy) * sunRect.zw;
  gl_Position = vec4(window * 2.0 - 1.0, 0.0, 1.0);
  kappa = ballOptics.x;
  planeOffsets = (vec2(planeDepth, planeDepth - slabThickness) + dot(ball.xyz, toSun)) / ball.w;
  if (planeOffsets.y >= 1.0)
  {
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0); // the ball ends before the slab: no fragments
  }
}

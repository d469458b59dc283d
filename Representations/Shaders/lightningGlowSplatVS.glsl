// The lightning glow's splats (vtkNimbusLightningGlowMapper): one camera-facing square
// of half-side `radius` (world units) per point source, two triangles whose six
// vertices carry the source's position and intensity and their corner (-1 or 1 each).
//VTK::System::Dec
in vec4 sourceMC;   // xyz: the source (model coordinates), w: its intensity I
in vec2 cornerIn;   // the vertex's corner of the square, in units of the radius
uniform mat4 MCVCMatrix;
uniform mat4 VCDCMatrix;
uniform float radius;
out vec2 offset;     // b / R across the square
out float intensity; // I

void main()
{
  vec4 centre = MCVCMatrix * vec4(sourceMC.xyz, 1.0);
  centre.xy += cornerIn * radius * centre.w;
  gl_Position = VCDCMatrix * centre;
  offset = cornerIn;
  intensity = sourceMC.w;
}

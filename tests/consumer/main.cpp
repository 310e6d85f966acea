// Renders a constant box to memory with the installed core library (volref::volref_core alone) and
// checks the closed form alpha = 1 - (1 - a)^(L / l) = 1 - 0.5^2 = 0.75 for a chord of 2, a = 0.5, l = 1.
#include <cmath>
#include <cstdio>

#include "volref_core.h"

int main() {
    volref::Scene s;
    volref::FieldSpec f;
    f.kind = volref::FieldSpec::Kind::Constant;
    f.value = 1.0;
    f.dims = {3, 3, 3};
    s.volume().source.field = f;
    s.volume().transfer.opacity = {{0.0, 0.5}};
    s.camera.type = volref::CameraSpec::Type::Orthographic;
    s.camera.eye = {1, 1, 5};
    s.camera.target = {1, 1, 0};
    s.camera.height = 1;
    s.image.width = s.image.height = 1;
    const volref::Image im = volref::render_scene(s);
    const double a = im.at(0, 0, 3);
    std::printf("alpha = %.17g\n", a);
    return std::fabs(a - 0.75) < 1e-14 ? 0 : 1;
}

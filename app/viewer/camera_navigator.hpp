#pragma once
// Camera navigation as pure functions of a camera and mouse input in widget pixels, so the
// viewer's gestures are unit-testable without a window. A camera moved by them has its near and
// far planes fitted again (a named view's given planes hold until the camera moves).
#include <QPointF>
#include <QSize>
#include <QString>

#include "mfr/scene/camera.hpp"
#include "mfr/scene/scene.hpp"

namespace navigation {

// Trackball: rotates the eye (and up) around the target; a drag across the whole view height
// turns by 180°.
mfr::Camera orbit(const mfr::Camera& camera, QPointF delta, QSize view);
// Moves eye and target together so the point under the cursor follows it (on the target plane).
mfr::Camera pan(const mfr::Camera& camera, QPointF delta, QSize view);
// Zooms by `steps` wheel notches (positive: closer) keeping the target-plane point under the
// cursor fixed: perspective moves the eye, orthographic shrinks the view height.
mfr::Camera zoomAt(const mfr::Camera& camera, QPointF cursor, QSize view, double steps);
// Perspective ↔ orthographic with the same framing at the target distance.
mfr::Camera toggledProjection(const mfr::Camera& camera);

enum class StandardView { Front, Back, Left, Right, Top, Bottom, Iso };
QString standardViewName(StandardView view);
// Looks at the visible objects from the given side, keeping the projection, framed like "fit".
mfr::Camera standardView(StandardView view, const mfr::Scene& scene, const mfr::Camera& current);

}  // namespace navigation

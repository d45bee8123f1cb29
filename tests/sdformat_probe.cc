// What Gazebo gets from a URDF or SDF file: libsdformat (Gazebo's parser and URDF converter) loads it
// and this prints the model's links and joints and each joint's spring and damping, one line each.
// Built by tests/test_robot_sdformat.py against the system's libsdformat (Debian: libsdformat-dev).
#include <iostream>
#include <sdf/sdf.hh>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: sdformat_probe FILE\n";
    return 2;
  }
  sdf::Root root;
  for (const auto& e : root.Load(argv[1])) std::cout << "error " << e.Message() << "\n";
  const sdf::Model* model = root.Model();
  if (model == nullptr) {
    std::cout << "links 0 joints 0\n";
    return 0;
  }
  std::cout << "links " << model->LinkCount() << " joints " << model->JointCount() << "\n";
  for (uint64_t i = 0; i < model->JointCount(); ++i) {
    const sdf::Joint* j = model->JointByIndex(i);
    std::cout << "joint " << j->Name();
    if (const sdf::JointAxis* a = j->Axis(0)) {
      std::cout << " k " << a->SpringStiffness() << " rest " << a->SpringReference() << " c " << a->Damping();
    }
    std::cout << "\n";
  }
  return 0;
}

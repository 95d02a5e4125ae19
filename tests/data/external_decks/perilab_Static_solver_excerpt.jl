    start_u = Data_Manager.get_field("Start_Values")
    coor = Data_Manager.get_field("Coordinates")
    external_forces = Data_Manager.get_field("External Forces")
    external_force_densities = Data_Manager.get_field("External Force Densities")
    force_densities = Data_Manager.get_field("Force Densities", "NP1")
    forces = Data_Manager.get_field("Forces", "NP1")
    volume = Data_Manager.get_field("Volume")
    active_nodes = Data_Manager.get_field("Active Nodes")
    active_list = Data_Manager.get_field("Active")
    for idt in iter
        Data_Manager.set_iteration(idt)
        #apply_bc_dirichlet(bcs, time) #-> Dirichlet
        apply_bc_dirichlet(["Forces", "Force Densities"],
                           bcs,
                           time,
                           step_time) #-> Dirichlet
        external_force_densities += external_forces ./ volume
        active_nodes = Data_Manager.get_field("Active Nodes")
        active_nodes = find_active_nodes(active_list, active_nodes,
                                         1:Data_Manager.get_nnodes())

